"""``symcat validate en50318`` says under its table that the presag is an assumption, and which
value it used, whether the quantities pass or fail (issue 30)."""
from symcat.validation import ANNEX_A_PRESAG, closing_lines


def _rows(ok: bool, value=1.0):
    return {250: [("contact_force_std_N", value, 0.0, 2.0, True), ("support_uplift_max_m", value, 0.0, 2.0, ok)]}


def test_failing_at_the_default_presag_names_it_with_the_passing_command():
    text = closing_lines(_rows(False), 55.0, 55.0, [20.0])
    first, second = text.splitlines()
    assert first.startswith("the failing quantities hinge on presag_mm (55 mm here, an assumption")
    assert ANNEX_A_PRESAG in first
    assert "--set presag_mm=20` passes" in second


def test_passing_runs_still_state_the_presag_used():
    text = closing_lines(_rows(True), 55.0, 55.0, [20.0])
    assert text.startswith("presag_mm = 55 mm (the model's default) is an assumption: " + ANNEX_A_PRESAG)
    assert "\n" not in text
    text = closing_lines(_rows(True), 20.0, 55.0, [20.0])
    assert text.startswith("presag_mm = 20 mm (set here; the default is 55 mm) is an assumption")


def test_failing_at_a_presag_the_user_set_states_it_too():
    text = closing_lines(_rows(False), 30.0, 55.0, [20.0])
    assert text.startswith("presag_mm = 30 mm (set here; the default is 55 mm) is an assumption")


def test_the_model_documents_the_presag_as_an_assumption():
    from symcat.model import load_model

    model = load_model("en50318")
    doc = model.run.__globals__["__doc__"]
    assert "The presag is an assumption" in doc and "not in the public record" in doc
    assert "assumption" in model.parameter("presag_mm").doc
