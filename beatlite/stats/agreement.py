"""Agreement between metrics and people: Bradley–Terry strengths from pairwise votes, Kendall's τ with intervals.

A listening (watching) test in the style of GENEA's asks people which of two videos looks more human-like. The
votes of ``K`` systems are a ``(K, K)`` win matrix, ``wins[i, j]`` = how often ``i`` was preferred to ``j``.
:func:`bradley_terry` turns it into one strength per system (the model ``P(i beats j) = p_i / (p_i + p_j)``),
and :func:`kendall_tau` / :func:`vote_agreement` measure how well a metric orders the systems as people do.

=========================  ===========================================================================
``bradley_terry``          maximum-likelihood strengths, minorisation-maximisation (Hunter 2004)
``bradley_terry_order``    the systems' order by those strengths, also when one group won every vote
``bradley_terry_step``     one MM update (the exercise of notebook 09)
``simulate_votes``         votes drawn from known strengths (checks that the fit recovers them)
``kendall_tau``            τ-b and its p-value (``scipy.stats.kendalltau``), bootstrap interval over items
``vote_agreement``         τ between a metric and the strengths, interval from resampling the votes
=========================  ===========================================================================

Example: two systems, 7 votes to 3, have strengths 0.7 and 0.3 (the closed form ``w / (w + l)``):

>>> import numpy as np
>>> bradley_terry(np.array([[0, 7], [3, 0]])).round(6).tolist()
[0.7, 0.3]

Taught in notebooks/09_scoring.ipynb, section 4 (agreement with people).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence

import numpy as np

__all__ = [
    "TauResult",
    "bradley_terry",
    "bradley_terry_order",
    "bradley_terry_step",
    "kendall_tau",
    "simulate_votes",
    "vote_agreement",
]


def _check_wins(wins: np.ndarray) -> np.ndarray:
    w = np.asarray(wins, dtype=np.float64)
    if w.ndim != 2 or w.shape[0] != w.shape[1] or w.shape[0] < 2:
        raise ValueError(f"wins must be a square (K, K) matrix with K >= 2, got shape {w.shape}")
    if not np.isfinite(w).all() or (w < 0).any():
        raise ValueError("wins must hold finite counts >= 0")
    w = w.copy()
    np.fill_diagonal(w, 0.0)
    played = (w + w.T).sum(axis=1)
    if (played == 0).any():
        raise ValueError(f"systems {np.flatnonzero(played == 0).tolist()} were never compared")
    return w


def bradley_terry_step(strengths: np.ndarray, wins: np.ndarray) -> np.ndarray:
    """One minorisation-maximisation update of the Bradley–Terry strengths (Hunter 2004, eq. 3).

    ``p_i <- W_i / sum_{j != i} n_ij / (p_i + p_j)``, with ``W_i`` the wins of ``i`` and ``n_ij = wins[i, j] +
    wins[j, i]`` the comparisons of ``i`` and ``j``; then normalised to sum 1.

    Parameters
    ----------
    strengths : (K,) float > 0
        Current strengths.
    wins : (K, K) float or int
        ``wins[i, j]``: votes preferring system ``i`` to system ``j`` (the diagonal is ignored).

    Returns
    -------
    (K,) float
        Updated strengths, summing to 1.

    Examples
    --------
    >>> bradley_terry_step(np.array([0.5, 0.5]), np.array([[0, 3], [1, 0]])).tolist()
    [0.75, 0.25]
    """
    w = _check_wins(wins)
    p = np.asarray(strengths, dtype=np.float64)
    n = w + w.T
    pair = p[:, None] + p[None, :]
    denom = np.divide(n, pair, out=np.zeros_like(n), where=n > 0).sum(axis=1)  # 0 where never compared
    new = w.sum(axis=1) / denom
    return new / new.sum()


def bradley_terry(wins: np.ndarray, *, max_iter: int = 10_000, tol: float = 1e-12) -> np.ndarray:
    """Maximum-likelihood Bradley–Terry strengths from a win matrix.

    The model: ``P(i preferred to j) = p_i / (p_i + p_j)``. Fitted by :func:`bradley_terry_step` from equal
    strengths until the largest change is below ``tol`` (Hunter 2004: each step increases the likelihood).

    The maximum-likelihood strengths are all positive exactly when the wins link every system to every other
    (the directed graph with an edge ``i -> j`` when ``i`` beat ``j`` at least once is strongly connected; Ford
    1957). Otherwise some group of systems won every vote against the others it met (separation): the
    likelihood grows as that group's strengths grow without bound relative to the rest, and its supremum is the
    limit in which every strongly connected group of the wins is infinitely stronger than the groups it beat. That
    limit is returned, found without iterating towards it: the strongest group (the one no other system ever
    beat) gets the strengths of a fit to its own votes, every other system 0, so ``P(strongest beats another) =
    1``. :func:`bradley_terry_order` gives the order of all systems in that limit.

    Parameters
    ----------
    wins : (K, K) float or int
        ``wins[i, j]``: votes preferring ``i`` to ``j``; the diagonal is ignored. Every system must have been
        compared at least once, and the comparisons must link all systems (no two groups of systems that were
        never compared with each other: the model cannot say how strong one group is against the other, and
        the fit would return an arbitrary split).
    max_iter : int
        Most MM steps.
    tol : float
        Stop when no strength changes by more than this.

    Returns
    -------
    (K,) float
        Strengths summing to 1 (ratios are what the model identifies; ``log p`` are the usual "BT scores");
        0 for the systems outside the strongest group when the votes are separated.

    Raises
    ------
    ValueError
        Not a square matrix of counts, a system never compared, systems in groups never compared, or separated
        votes with two or more groups that nobody beat (their relative strengths are not identified).

    Examples
    --------
    Two systems: the strength is the share of wins, ``w / (w + l)``.

    >>> bradley_terry(np.array([[0, 3], [1, 0]])).tolist()
    [0.75, 0.25]

    System 0 won every vote: it is infinitely stronger than the others (the limit, not 10,000 slow MM steps).

    >>> bradley_terry(np.array([[0, 2, 3], [0, 0, 1], [0, 2, 0]])).tolist()
    [1.0, 0.0, 0.0]
    """
    w = _linked_wins(wins)
    n_groups, group = _win_groups(w)
    if n_groups == 1:
        return _mm(w, max_iter, tol)
    beaten = _group_wins(w, n_groups, group).any(axis=0)
    tops = np.flatnonzero(~beaten)
    if len(tops) > 1:
        groups = [np.flatnonzero(group == g).tolist() for g in tops]
        raise ValueError(
            f"the groups of systems {groups} each won every vote against the systems outside it, and no vote "
            "decided between them: their relative strengths are not identified"
        )
    top = np.flatnonzero(group == tops[0])
    p = np.zeros(len(w))
    p[top] = _mm(w[np.ix_(top, top)], max_iter, tol) if len(top) > 1 else 1.0
    return p


def bradley_terry_order(wins: np.ndarray, *, max_iter: int = 10_000, tol: float = 1e-12) -> np.ndarray:
    """The order of the systems by their maximum-likelihood Bradley–Terry strengths, also for separated votes.

    Without separation (see :func:`bradley_terry`) this is :func:`bradley_terry` itself. With it, the
    strongly connected groups of the wins are ranked by who beat whom (a group above every group it beat) and
    the systems inside a group by a fit to that group's own votes: the order of the strengths in the limit that
    maximises the likelihood, which :func:`bradley_terry` collapses to 0 below the strongest group.

    Parameters
    ----------
    wins : (K, K) float or int
        As :func:`bradley_terry` reads them.
    max_iter, tol : int, float
        Of the fits (:func:`bradley_terry`).

    Returns
    -------
    (K,) float
        Without separation the strengths; with it the ranks ``0`` (weakest), ``1``, ... (equal strengths share
        a rank). Only the order is meaningful (e.g. for :func:`kendall_tau`).

    Raises
    ------
    ValueError
        As :func:`bradley_terry`, and for separated votes whose groups have no single order (two groups that
        no vote decided between, as when both beat a third in every vote and never met).

    Examples
    --------
    System 0 won every vote; 1 and 2 split theirs 3 to 1: 0 first, then 1, then 2.

    >>> bradley_terry_order(np.array([[0, 2, 2], [0, 0, 3], [0, 1, 0]])).tolist()
    [2.0, 1.0, 0.0]
    """
    order = _limit_order(_linked_wins(wins), max_iter, tol)
    if order is None:
        raise ValueError(
            "the votes are separated into groups of systems that no vote orders against each other: their order "
            "is not identified"
        )
    return order


def _mm(w: np.ndarray, max_iter: int, tol: float) -> np.ndarray:
    """:func:`bradley_terry_step` from equal strengths until no strength changes by ``tol`` (or ``max_iter``)."""
    p = np.full(len(w), 1.0 / len(w))
    for _ in range(max_iter):
        new = bradley_terry_step(p, w)
        if np.abs(new - p).max() < tol:
            return new
        p = new
    return p


def _linked_wins(wins: np.ndarray) -> np.ndarray:
    """:func:`_check_wins`, then ``ValueError`` when the comparisons fall into groups never compared."""
    from scipy.sparse.csgraph import connected_components

    w = _check_wins(wins)
    n_parts, part = connected_components(w + w.T > 0, directed=False)
    if n_parts > 1:
        groups = [np.flatnonzero(part == k).tolist() for k in range(n_parts)]
        raise ValueError(
            f"the comparisons fall into {n_parts} groups of systems never compared with each other: {groups}; "
            "their relative strengths are not identified"
        )
    return w


def _win_groups(w: np.ndarray) -> tuple[int, np.ndarray]:
    """The strongly connected groups of the win graph (``i -> j`` when ``i`` beat ``j``): count, (K,) labels."""
    from scipy.sparse.csgraph import connected_components

    return connected_components(w > 0, directed=True, connection="strong")


def _group_wins(w: np.ndarray, n_groups: int, group: np.ndarray) -> np.ndarray:
    """``(G, G)`` bool: a system of group ``a`` beat one of group ``b != a`` (the groups' condensed graph)."""
    beat = np.zeros((n_groups, n_groups), dtype=bool)
    i, j = np.nonzero(w > 0)
    beat[group[i], group[j]] = True
    np.fill_diagonal(beat, False)
    return beat


def _limit_order(w: np.ndarray, max_iter: int, tol: float) -> np.ndarray | None:
    """:func:`bradley_terry_order` of checked, linked wins; None when separated groups have no single order."""
    n_groups, group = _win_groups(w)
    if n_groups == 1:
        return _mm(w, max_iter, tol)
    beat = _group_wins(w, n_groups, group)
    left, tiers = list(range(n_groups)), []
    while left:  # the groups' order (a unique topological order of the condensed graph, strongest first)
        free = [a for a in left if not beat[left, a].any()]
        if len(free) != 1:
            return None
        tiers.append(free[0])
        left.remove(free[0])
    keys: list[tuple[int, float]] = [(0, 0.0)] * len(w)
    for tier, g in enumerate(tiers):
        members = np.flatnonzero(group == g)
        p = _mm(w[np.ix_(members, members)], max_iter, tol) if len(members) > 1 else np.ones(1)
        for m, pm in zip(members, p, strict=True):
            keys[m] = (-tier, float(pm))
    rank = {key: float(r) for r, key in enumerate(sorted(set(keys)))}
    return np.array([rank[key] for key in keys])


def simulate_votes(strengths: Sequence[float], votes_per_pair: int, *, seed: int = 0) -> np.ndarray:
    """Pairwise votes of simulated raters who follow the Bradley–Terry model with the given strengths.

    Parameters
    ----------
    strengths : (K,) float > 0
        The true strengths.
    votes_per_pair : int
        Votes cast on every pair ``i < j``.
    seed : int
        ``numpy.random.default_rng`` seed.

    Returns
    -------
    (K, K) int
        ``wins[i, j] ~ Binomial(votes_per_pair, p_i / (p_i + p_j))`` and ``wins[j, i] = votes_per_pair - wins[i, j]``.

    Examples
    --------
    >>> w = simulate_votes([0.6, 0.3, 0.1], 100, seed=0)
    >>> int((w + w.T)[0, 1]), int(np.trace(w))
    (100, 0)
    """
    p = np.asarray(strengths, dtype=np.float64)
    if p.ndim != 1 or len(p) < 2 or (p <= 0).any():
        raise ValueError("strengths must be a 1-D array of K >= 2 positive numbers")
    rng = np.random.default_rng(seed)
    wins = np.zeros((len(p), len(p)), dtype=np.int64)
    i, j = np.triu_indices(len(p), k=1)
    wins[i, j] = rng.binomial(int(votes_per_pair), p[i] / (p[i] + p[j]))
    wins[j, i] = int(votes_per_pair) - wins[i, j]
    return wins


@dataclasses.dataclass(frozen=True)
class TauResult:
    """Kendall's τ-b of two orderings with its p-value and an interval.

    Attributes
    ----------
    tau : float
        ``scipy.stats.kendalltau(a, b).statistic`` (τ-b: ties corrected), in [-1, 1].
    p_value : float
        Two-sided p-value of τ = 0 (scipy: exact for small samples without ties).
    low, high : float
        The interval (NaN when none was asked for).
    n : int
        Items (systems) ranked.
    level : float
        Coverage of the interval.
    method : str
        How the interval was made (``"items"``, ``"votes"`` or ``""``).

    Examples
    --------
    ``str`` gives the one line a report prints (the interval only when one was made):

    >>> print(TauResult(tau=0.6667, p_value=0.3333, low=float("nan"), high=float("nan"), n=4))
    tau = +0.67, p = 0.333 (n = 4)
    >>> print(TauResult(tau=0.5, p_value=0.04, low=0.1, high=0.8, n=10, method="items"))
    tau = +0.50, 95 % interval [+0.10, +0.80], p = 0.04 (n = 10)
    """

    tau: float
    p_value: float
    low: float
    high: float
    n: int
    level: float = 0.95
    method: str = ""

    def __str__(self) -> str:
        ci = f", {100 * self.level:g} % interval [{self.low:+.2f}, {self.high:+.2f}]" if self.method else ""
        return f"tau = {self.tau:+.2f}{ci}, p = {self.p_value:.3g} (n = {self.n})"


def _tau(a: np.ndarray, b: np.ndarray) -> float:
    from scipy.stats import kendalltau

    return float(kendalltau(a, b).statistic)


def kendall_tau(
    a: Sequence[float], b: Sequence[float], *, n_boot: int = 0, seed: int = 0, level: float = 0.95
) -> TauResult:
    """Kendall's τ-b between two score lists, with a percentile bootstrap interval over the items.

    Parameters
    ----------
    a, b : (n,) float
        Scores of the same ``n`` items (e.g. systems: a metric and a human rating). NaN pairs are dropped.
    n_boot : int
        Bootstrap resamples of the items (pairs ``(a_i, b_i)`` drawn with replacement); 0: no interval. A
        resample in which one side is constant has no τ and is left out. With few items the interval is coarse,
        and when the items agree perfectly every resample does too, so the interval collapses onto τ: read the
        p-value as well.
    seed : int
        ``numpy.random.default_rng`` seed of the resamples.
    level : float
        Coverage of the central percentile interval.

    Returns
    -------
    TauResult

    Examples
    --------
    >>> r = kendall_tau([1.0, 2.0, 3.0, 4.0], [10.0, 30.0, 20.0, 40.0])
    >>> round(r.tau, 4), round(r.p_value, 4)  # 5 of the 6 pairs agree: (5 - 1) / 6
    (0.6667, 0.3333)
    """
    x, y = np.asarray(a, dtype=np.float64), np.asarray(b, dtype=np.float64)
    if x.shape != y.shape or x.ndim != 1:
        raise ValueError(f"a and b must be 1-D of the same length, got {x.shape} and {y.shape}")
    keep = np.isfinite(x) & np.isfinite(y)
    x, y = x[keep], y[keep]
    if len(x) < 2:
        raise ValueError("need at least 2 items with finite scores")
    from scipy.stats import kendalltau

    res = kendalltau(x, y)
    low = high = float("nan")
    if n_boot > 0:
        rng = np.random.default_rng(seed)
        draws = []
        for _ in range(n_boot):
            idx = rng.integers(len(x), size=len(x))
            if np.ptp(x[idx]) > 0 and np.ptp(y[idx]) > 0:
                draws.append(_tau(x[idx], y[idx]))
        if draws:
            q = 50 * (1 - level)
            low, high = (float(v) for v in np.percentile(draws, [q, 100 - q]))
    return TauResult(
        float(res.statistic), float(res.pvalue), low, high, len(x), level, "items" if n_boot else ""
    )


def vote_agreement(
    scores: Sequence[float], wins: np.ndarray, *, n_boot: int = 1000, seed: int = 0, level: float = 0.95
) -> TauResult:
    """Kendall's τ between a metric's scores of ``K`` systems and their Bradley–Terry strengths from votes.

    The interval answers "how much would τ move if the same raters voted again?": each resample redraws every
    pair's votes, ``wins*[i, j] ~ Binomial(n_ij, wins[i, j] / n_ij)`` (the pair's own count ``n_ij`` kept), refits
    :func:`bradley_terry` and recomputes τ. It does not cover other systems, other test takes or other raters'
    tastes. τ is taken against :func:`bradley_terry_order` (the strengths themselves unless a group of systems won
    every vote against the rest, which few votes per pair and their resamples often do); a resample whose
    separated groups have no single order has no τ and is left out.

    Parameters
    ----------
    scores : (K,) float
        The metric's value per system (lower-is-better metrics give negative τ when they agree with people).
    wins : (K, K) int
        Votes, as :func:`bradley_terry` reads them.
    n_boot : int
        Resamples of the votes (0: no interval).
    seed : int
    level : float

    Returns
    -------
    TauResult
        ``tau`` and ``p_value`` of ``kendall_tau(scores, bradley_terry_order(wins))``, the interval over vote
        resamples.

    Raises
    ------
    ValueError
        ``wins`` not a square count matrix, a system never compared, ``scores`` not one value per system, or
        votes whose separated groups have no single order (:func:`bradley_terry_order`: two groups each won
        every vote against the rest).

    Examples
    --------
    >>> wins = simulate_votes([0.5, 0.3, 0.2], 200, seed=1)
    >>> round(vote_agreement([3.0, 2.0, 1.0], wins, n_boot=0).tau, 6)
    1.0
    """
    w = _check_wins(wins)
    s = np.asarray(scores, dtype=np.float64)
    if s.shape != (len(w),):
        raise ValueError(f"scores must have one value per system ({len(w)}), got shape {s.shape}")
    base = kendall_tau(s, bradley_terry_order(w))
    if n_boot <= 0:
        return base
    rng = np.random.default_rng(seed)
    n = w + w.T
    i, j = np.triu_indices(len(w), k=1)
    share = np.divide(w[i, j], n[i, j], out=np.zeros(len(i)), where=n[i, j] > 0)
    draws = []
    for _ in range(n_boot):
        redrawn = np.zeros_like(w)
        redrawn[i, j] = rng.binomial(n[i, j].astype(np.int64), share)
        redrawn[j, i] = n[i, j] - redrawn[i, j]
        order = _limit_order(redrawn, 10_000, 1e-12)  # None: separated groups in no single order
        draws.append(np.nan if order is None else kendall_tau(s, order).tau)
    q = 50 * (1 - level)
    low, high = (float(v) for v in np.nanpercentile(draws, [q, 100 - q]))
    return dataclasses.replace(base, low=low, high=high, level=level, method="votes")
