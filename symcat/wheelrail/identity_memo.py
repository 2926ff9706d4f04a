"""A small cache keyed by object identity and values, for results derived from immutable objects
that are not hashable (profiles, cross-sections): the 8 wheels of a vehicle share one profile
pair, and building each wheel's lookups, creep function and rest geometry anew was two thirds of
a vehicle model's 0.24 s set-up."""
from __future__ import annotations

from collections import OrderedDict


class IdentityMemo:
    """``get(objects, values, build)``: ``build()``'s result for the same objects (by identity)
    and equal ``values`` (hashable), built once and kept, the oldest dropped beyond ``size``.
    The cache holds the objects themselves, so their identities cannot be reused while cached.

    Parameters
    ----------
    size : int
        Entries kept.
    """

    def __init__(self, size: int = 32):
        self.size = int(size)
        self._entries: OrderedDict = OrderedDict()

    def get(self, objects: tuple, values: tuple, build):
        key = (tuple(id(o) for o in objects), values)
        hit = self._entries.get(key)
        if hit is not None and all(a is b for a, b in zip(hit[0], objects)):
            self._entries.move_to_end(key)
            return hit[1]
        result = build()
        self._entries[key] = (tuple(objects), result)
        if len(self._entries) > self.size:
            self._entries.popitem(last=False)
        return result

    def __len__(self) -> int:
        return len(self._entries)
