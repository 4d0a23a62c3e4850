"""Which cables of a framework can be taut together: each such taut set is a polynomial system
of its own (the complex route solves each; the real route classifies each root by its set)."""

from __future__ import annotations


def taut_sets(fw) -> list[tuple[str, ...]]:
    """The subsets of the cables that can be taut together (all taut first), each its own
    polynomial system: a cable longer than its free length in every pose is in all of them, one
    never longer in none (model.framework.reach bounds the lengths over every pose), and a set
    no pose can hold is left out (pruned_taut_sets says which and why)."""
    return split_taut_sets(fw)[0]


def pruned_taut_sets(fw) -> dict:
    """The taut sets no pose can hold (model.framework.prune: bound smoothing), each with its
    proof (a prune.Pruned)."""
    return split_taut_sets(fw)[1]


def split_taut_sets(fw) -> tuple[list[tuple[str, ...]], dict]:
    """(taut_sets, pruned_taut_sets) from one pass of the pruning."""
    from .prune import prune

    found = {t: prune(fw, t) for t in _cable_subsets(fw)}
    return [t for t, p in found.items() if p is None], {
        t: p for t, p in found.items() if p is not None
    }


def _cable_subsets(fw) -> list[tuple[str, ...]]:
    """Every subset of the cables reach.cable_states leaves open, with the always-taut ones."""
    from itertools import combinations

    from .reach import cable_states

    states = cable_states(fw)
    always = tuple(n for n, s in states.items() if s == "taut")
    either = [n for n, s in states.items() if s == "either"]
    subsets = [c for r in range(len(either), -1, -1) for c in combinations(either, r)]
    order = [c.name for c in fw.cables]
    return [tuple(sorted(always + c, key=order.index)) for c in subsets]
