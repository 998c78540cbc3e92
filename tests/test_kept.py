"""Kept: a few values by key, made once, the least recently used dropped first."""

from __future__ import annotations

from ocpkit.kept import Kept


def test_a_value_is_made_once_and_the_least_recently_used_goes_first():
    kept, made = Kept(2), []

    def make(value):
        return lambda: made.append(value) or value

    assert kept.get("a", make(1)) == 1 and kept.get("a", make(9)) == 1 and made == [1]
    kept.get("b", make(2))
    assert kept["a"] == 1  # "a" used last: "b" is now the oldest
    kept.get("c", make(3))
    assert "a" in kept and "c" in kept and "b" not in kept and len(kept) == 2
    kept.clear()
    assert len(kept) == 0 and kept.get("a", make(4)) == 4 and made == [1, 2, 3, 4]
