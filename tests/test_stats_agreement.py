"""Bradley–Terry strengths and Kendall's τ (beatlite.stats.agreement) against closed forms and scipy."""

from __future__ import annotations

import itertools

import numpy as np
import pytest
import scipy.stats

from beatlite.stats.agreement import (
    bradley_terry,
    bradley_terry_order,
    bradley_terry_step,
    kendall_tau,
    simulate_votes,
    vote_agreement,
)


@pytest.mark.parametrize(("won", "lost"), [(7, 3), (1, 9), (50, 50), (0, 4)])
def test_two_systems_strength_is_the_share_of_wins(won, lost):
    p = bradley_terry(np.array([[0, won], [lost, 0]]))
    np.testing.assert_allclose(p, [won / (won + lost), lost / (won + lost)], atol=1e-9)


def test_mm_step_hand_computed():
    # p = (1/3, 1/3, 1/3); wins: 0 beat 1 twice, 1 beat 0 once, 0 beat 2 once, 2 beat 1 three times
    wins = np.array([[0, 2, 1], [1, 0, 0], [0, 3, 0]])
    # n01 = 3, n02 = 1, n12 = 3; every p_i + p_j = 2/3, so p_i <- W_i / (1.5 * sum_j n_ij)
    raw = np.array([3 / (1.5 * 4), 1 / (1.5 * 6), 3 / (1.5 * 4)])
    np.testing.assert_allclose(bradley_terry_step(np.full(3, 1 / 3), wins), raw / raw.sum())


def test_fit_satisfies_the_likelihood_equations():
    """At the maximum, each system's wins equal its expected wins: W_i = sum_j n_ij p_i / (p_i + p_j)."""
    wins = np.array([[0, 12, 9, 15], [8, 0, 11, 10], [11, 9, 0, 14], [5, 10, 6, 0]])
    p = bradley_terry(wins)
    n = wins + wins.T
    expected = (n * p[:, None] / (p[:, None] + p[None, :])).sum(axis=1)
    np.testing.assert_allclose(expected, wins.sum(axis=1), rtol=1e-8)
    assert np.isclose(p.sum(), 1.0)


def test_fit_equals_scipy_maximum_likelihood():
    """The MM fit reaches the optimum that a general-purpose optimiser finds on the log-likelihood."""
    from scipy.optimize import minimize

    wins = simulate_votes([0.4, 0.3, 0.2, 0.1], 30, seed=3).astype(float)

    def nll(theta):
        t = np.concatenate([[0.0], theta])  # log-strengths, the first fixed
        return -(wins * (t[:, None] - np.logaddexp(t[:, None], t[None, :]))).sum()

    theta = minimize(nll, np.zeros(3), method="BFGS", options={"gtol": 1e-10}).x
    want = np.exp(np.concatenate([[0.0], theta]))
    np.testing.assert_allclose(bradley_terry(wins), want / want.sum(), rtol=1e-5)


def test_recovers_a_known_order_from_many_votes():
    truth = np.array([0.05, 0.4, 0.1, 0.25, 0.2])
    p = bradley_terry(simulate_votes(truth, 2000, seed=0))
    assert list(np.argsort(p)) == list(np.argsort(truth))
    np.testing.assert_allclose(p, truth, rtol=0.1)


def test_simulated_votes_are_complementary_and_unbiased():
    wins = simulate_votes([0.75, 0.25], 4000, seed=1)
    assert wins[0, 1] + wins[1, 0] == 4000 and np.trace(wins) == 0
    assert abs(wins[0, 1] / 4000 - 0.75) < 0.03  # 5 standard errors of a share of 4000 votes


def test_bad_win_matrices_are_refused():
    with pytest.raises(ValueError, match="square"):
        bradley_terry(np.zeros((2, 3)))
    with pytest.raises(ValueError, match="never compared"):
        bradley_terry(np.array([[0, 1, 0], [1, 0, 0], [0, 0, 0]]))
    with pytest.raises(ValueError, match=">= 0"):
        bradley_terry(np.array([[0, -1], [1, 0]]))


def test_systems_in_groups_never_compared_are_refused():
    # {0, 1} and {2, 3} were each compared only inside their pair: p0 / p2 has no maximum-likelihood value
    # (the fit used to return [0.375, 0.125, 0.125, 0.375], an arbitrary even split of the two pairs)
    wins = np.array([[0, 3, 0, 0], [1, 0, 0, 0], [0, 0, 0, 1], [0, 0, 3, 0]])
    with pytest.raises(ValueError, match=r"2 groups .*\[\[0, 1\], \[2, 3\]\]"):
        bradley_terry(wins)
    with pytest.raises(ValueError, match="2 groups"):
        vote_agreement([1.0, 2.0, 3.0, 4.0], wins, n_boot=0)
    wins[1, 2] = 1  # one vote links the groups: identified
    assert np.isclose(bradley_terry(wins).sum(), 1.0)


def test_kendall_tau_equals_scipy_and_the_pair_count():
    rng = np.random.default_rng(0)
    for n in (5, 8, 12):
        a, b = rng.normal(size=n), rng.normal(size=n)
        pairs = list(itertools.combinations(range(n), 2))
        concordant = sum(np.sign(a[i] - a[j]) == np.sign(b[i] - b[j]) for i, j in pairs)
        r = kendall_tau(a, b)
        assert np.isclose(r.tau, (2 * concordant - len(pairs)) / len(pairs))
        assert np.isclose(r.tau, scipy.stats.kendalltau(a, b).statistic)
        assert np.isclose(r.p_value, scipy.stats.kendalltau(a, b).pvalue)


def test_kendall_tau_exact_p_value_of_a_perfect_order_of_five():
    # 1 of the 5! = 120 orders agrees perfectly, 1 perfectly reversed: two-sided p = 2 / 120
    r = kendall_tau([1, 2, 3, 4, 5], [2, 4, 6, 8, 10])
    assert np.isclose(r.tau, 1.0) and np.isclose(r.p_value, 2 / 120)


def test_kendall_tau_bootstrap_interval_contains_tau_and_is_seeded():
    a, b = [1, 2, 3, 4, 5, 6], [2, 1, 4, 3, 6, 5]
    r = kendall_tau(a, b, n_boot=300, seed=4)
    assert r.low <= r.tau <= r.high and r.method == "items" and r.n == 6
    assert kendall_tau(a, b, n_boot=300, seed=4) == r
    assert np.isnan(kendall_tau(a, b).low)


def test_kendall_tau_interval_is_nan_without_a_usable_resample():
    # a constant side has no tau in any resample; nor do the 2-item resamples that draw one item twice
    # (seed 0 draws only such with n_boot=1): the interval used to raise IndexError from np.percentile([])
    r = kendall_tau([1.0, 1.0, 1.0], [1.0, 2.0, 3.0], n_boot=50)
    assert np.isnan(r.tau) and np.isnan(r.low) and np.isnan(r.high) and r.method == "items"
    r = kendall_tau([1.0, 2.0], [1.0, 2.0], n_boot=1, seed=0)
    assert r.tau == 1.0 and np.isnan(r.low) and np.isnan(r.high)


def test_kendall_tau_drops_nan_pairs():
    r = kendall_tau([1.0, np.nan, 3.0, 2.0], [1.0, 5.0, 3.0, 2.0])
    assert r.n == 3 and np.isclose(r.tau, 1.0)


def test_vote_agreement_interval_widens_with_fewer_votes():
    truth = [0.3, 0.25, 0.2, 0.15, 0.1]
    scores = [5.0, 4.0, 3.0, 2.0, 1.0]
    many = vote_agreement(scores, simulate_votes(truth, 500, seed=0), n_boot=200, seed=0)
    few = vote_agreement(scores, simulate_votes(truth, 5, seed=0), n_boot=200, seed=0)
    assert many.method == "votes" and many.low <= many.tau <= many.high
    assert (few.high - few.low) > (many.high - many.low)
    assert many.tau == kendall_tau(scores, bradley_terry(simulate_votes(truth, 500, seed=0))).tau


def _bounded_mle(wins, bound=25.0):
    """scipy's maximum of the log-likelihood with every log-strength in [-bound, bound]: where the votes are
    separated the maximum has no finite location, and the bounded one approaches the limit as the bound grows."""
    from scipy.optimize import minimize

    wins = np.asarray(wins, dtype=float)

    def nll(t):
        return -(wins * (t[:, None] - np.logaddexp(t[:, None], t[None, :]))).sum()

    bounds = [(-bound, bound)] * len(wins)
    theta = minimize(nll, np.zeros(len(wins)), method="L-BFGS-B", bounds=bounds, options={"ftol": 1e-15}).x
    p = np.exp(theta - theta.max())
    return p / p.sum()


# system 0 won all its 9 votes; 1 and 2 split theirs 3 to 1; 3 lost all its 6 votes
SEPARATED = np.array([[0, 3, 2, 4], [0, 0, 3, 1], [0, 1, 0, 1], [0, 0, 0, 0]])


def test_separated_votes_give_the_likelihoods_limit_at_once(monkeypatch):
    """When a system wins every vote the maximum-likelihood strengths are on the boundary: bradley_terry used to
    run all 10,000 MM steps towards it (and vote_agreement that many per resample: ~3 min at its default 1,000).
    Now the limit is returned: the unbeaten system 0 gets strength 1, the others 0, as scipy's bounded maximum
    approaches."""
    from beatlite.stats import agreement

    steps = []
    step = agreement.bradley_terry_step
    monkeypatch.setattr(agreement, "bradley_terry_step", lambda p, w: steps.append(1) or step(p, w))
    p = bradley_terry(SEPARATED)
    assert p.tolist() == [1.0, 0.0, 0.0, 0.0]
    # the bounded optimum stops with the beaten systems' strengths near 1e-7, where the likelihood no longer
    # changes in float64 (at the bounds they would be e^-50); 1e-5 leaves a margin of 100
    np.testing.assert_allclose(p, _bounded_mle(SEPARATED), atol=1e-5)
    assert len(steps) < 100, len(steps)  # an MM fit of 2 systems at most, not 10,000 steps


def test_the_order_in_the_separated_limit_is_the_bounded_maximums():
    """bradley_terry_order ranks 0 (unbeaten) above 1 and 2 (their own fit: 3 to 1, so 1 first) above 3
    (beaten by all), the order of scipy's bounded maximum; within a group the strengths' ratio is the group's
    own closed form w / l."""
    order = bradley_terry_order(SEPARATED)
    assert order.tolist() == [3.0, 2.0, 1.0, 0.0]
    bounded = _bounded_mle(SEPARATED)
    assert list(np.argsort(bounded)) == list(np.argsort(order))
    assert np.isclose(bounded[1] / bounded[2], 3.0, rtol=1e-3)  # the 1-vs-2 votes set it; 0's pull is e^-50
    # two systems that split their votes and beat the third in every vote: the pair's share, the third 0
    np.testing.assert_allclose(bradley_terry(np.array([[0, 3, 2], [1, 0, 5], [0, 0, 0]])), [0.75, 0.25, 0.0])
    # no separation: the order is the strengths themselves
    wins = simulate_votes([0.4, 0.3, 0.2, 0.1], 30, seed=3)
    assert np.array_equal(bradley_terry_order(wins), bradley_terry(wins))


def test_separated_groups_without_one_order_are_refused():
    # 0 and 1 each beat 2 in every vote and never met: which is stronger is not identified
    wins = np.array([[0, 0, 2], [0, 0, 1], [0, 0, 0]])
    with pytest.raises(ValueError, match=r"groups of systems \[\[0\], \[1\]\] each won every vote"):
        bradley_terry(wins)
    with pytest.raises(ValueError, match="not identified"):
        bradley_terry_order(wins)
    # 0 beat 1 and 2 in every vote, 1 and 2 never met: 0 is the limit's only strong system, 1 vs 2 has no order
    wins = np.array([[0, 2, 1], [0, 0, 0], [0, 0, 0]])
    assert bradley_terry(wins).tolist() == [1.0, 0.0, 0.0]
    with pytest.raises(ValueError, match="not identified"):
        bradley_terry_order(wins)


def test_vote_agreement_on_separated_votes_takes_few_mm_steps(monkeypatch):
    """Every resample of a pair voted one way only is separated too: each took 10,000 MM steps."""
    from beatlite.stats import agreement

    steps = []
    step = agreement.bradley_terry_step
    monkeypatch.setattr(agreement, "bradley_terry_step", lambda p, w: steps.append(1) or step(p, w))
    r = vote_agreement([4.0, 3.0, 2.0, 1.0], SEPARATED, n_boot=50, seed=0)
    assert r.tau == 1.0 and r.low <= r.tau <= r.high and r.method == "votes"
    assert len(steps) < 50 * 200, len(steps)  # was 50 * 10,000 and more
