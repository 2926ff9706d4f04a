"""Pantograph/catenary passages on the shared multibody path: pantographs as scene bodies under the
catenary scene (:mod:`.scene_passage`), their EN 50318 statistics (:mod:`.statistics`), the
passage's section and duration (:mod:`.passage`), records and outputs."""
from .scene_record import load_passage

__all__ = ["load_passage"]
