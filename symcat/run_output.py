"""Where a run writes: the ``--out`` folder and the ``--summary`` file, checked before any work.

A run checks both paths before it computes anything (a path that cannot be written is found in
a second, not after an hour of computing), writes its JSON whole (never half a file), and
records the files it wrote in its ``summary.json``: a later run into the same folder first
removes the files of the earlier one (and only those), so runs never mix.
"""
from __future__ import annotations

import json
import os
from pathlib import Path

from .errors import ParameterError

#: The file of the ``--out`` folder that lists a run's outputs (with its summary).
SUMMARY_NAME = "summary.json"


def _probe_writable(folder: Path, option: str, path: Path) -> None:
    probe = folder / f".symcat-write-test-{os.getpid()}"
    try:
        probe.write_bytes(b"")
        probe.unlink()
    except OSError as err:
        raise ParameterError(f"{option} {path}: cannot write in {folder} ({err.strerror or err})") from None


def _missing_parents(folder: Path) -> list[Path]:
    """The folders of ``folder``'s path (itself included) that do not exist, outermost first."""
    missing = []
    for f in [folder, *folder.parents]:
        if f.exists():
            break
        missing.append(f)
    return missing[::-1]


class OutputPaths:
    """The checked ``--out`` folder and ``--summary`` file of one run.

    The folders it had to create are removed again by :meth:`discard` if the run ends before
    writing anything (bad input found late), so that nothing is left behind.

    Parameters
    ----------
    out : path or None
        Folder for plots, ParaView files and ``summary.json``.
    summary : path or None
        The summary JSON file.
    labels : tuple of str
        How the two are named in messages (``("--out", "--summary")`` on the command line).

    Raises
    ------
    ParameterError
        One line naming the option, the path and why it cannot be written.
    """

    def __init__(self, out=None, summary=None, labels=("out", "summary_path")):
        self.out = None if out is None else Path(out)
        self.summary = None if summary is None else Path(summary)
        self.created: list[Path] = []
        out_label, summary_label = labels
        if self.out is not None:
            if self.out.exists() and not self.out.is_dir():
                raise ParameterError(f"{out_label} {self.out}: is an existing file; give a folder (created if missing)")
            self._make(self.out, out_label, self.out)
            _probe_writable(self.out, out_label, self.out)
        if self.summary is not None:
            if self.summary.is_dir():
                raise ParameterError(f"{summary_label} {self.summary}: is a folder; give the path of a .json file")
            parent = self.summary.parent
            if parent.exists() and not parent.is_dir():
                raise ParameterError(f"{summary_label} {self.summary}: {parent} is a file, not a folder")
            self._make(parent, summary_label, self.summary)
            _probe_writable(parent, summary_label, self.summary)

    def _make(self, folder: Path, label: str, path: Path) -> None:
        missing = _missing_parents(folder)
        try:
            folder.mkdir(parents=True, exist_ok=True)
        except OSError as err:
            raise ParameterError(f"{label} {path}: cannot create the folder {folder} ({err.strerror or err})") from None
        self.created += [m for m in missing if m not in self.created]

    def discard(self) -> None:
        """Remove the folders this run created, if still empty (the run wrote nothing)."""
        for folder in reversed(self.created):
            try:
                folder.rmdir()
            except OSError:
                pass
        self.created = []

    def clear_previous_run(self) -> list[str]:
        """Remove the files an earlier run listed in ``<out>/summary.json`` (other files are
        kept); the names removed."""
        if self.out is None:
            return []
        try:
            listed = json.loads((self.out / SUMMARY_NAME).read_text()).get("files", [])
        except (OSError, ValueError, AttributeError):
            return []
        root = self.out.resolve()
        removed = []
        for name in [*listed, SUMMARY_NAME]:
            path = (self.out / str(name)).resolve()
            if root not in path.parents or not path.is_file():
                continue  # only files inside the folder
            path.unlink()
            removed.append(str(name))
            for parent in path.parents:
                if parent == root:
                    break
                try:
                    parent.rmdir()  # a subfolder the earlier run made, now empty
                except OSError:
                    break
        return removed


def write_json(path: Path, data: dict, default=None) -> None:
    """Write ``data`` as JSON so that a reader never sees half a file."""
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    try:
        tmp.write_text(json.dumps(data, indent=1, default=default) + "\n")
        os.replace(tmp, path)
    finally:
        tmp.unlink(missing_ok=True)
