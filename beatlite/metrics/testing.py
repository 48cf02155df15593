"""The metric contract: what every entry of :data:`~beatlite.metrics.scoring.METRICS` must satisfy.

As :func:`beatlite.models.testing.check_model` does for models (and scikit-learn's ``check_estimator`` for
estimators), :func:`check_metric` states the rules one metric key must keep, so a registered metric is checked
the same way as the built-in ones (``tests/test_metrics_contract.py`` runs it over the registry):

- it names its variant and its source (``describe``, ``source``);
- scored on the ground truth itself, its value lies in its ``bounds`` and equals its ``perfect`` value when it
  declares one (FGD 0, PCK 1, MPJPE 0);
- scored on a degraded system (the ground truth with noise on its bone directions), its value lies in its
  ``bounds`` and, when the metric declares ``perfect``, is strictly worse than it;
- a declared ``perfect`` value sits at the better end of the bounds (``higher_is_better`` says which end).

"""

from __future__ import annotations

import math

from beatlite.metrics.scoring import Metric

#: Tolerance of "equals its perfect value" (FGD of a set of features against itself is ~1e-13, not 0).
PERFECT_ATOL = 1e-6


def check_metric(key: str, metric: Metric, *, truth_value: float, degraded_value: float) -> None:
    """Assert the contract of one metric from its values on the ground truth and on a degraded system.

    Parameters
    ----------
    key : str
        The metric's key in ``METRICS`` (for the messages).
    metric : Metric
    truth_value, degraded_value : float
        ``evaluate(...)`` of the ground truth scored against itself, and of a degraded system.

    Raises
    ------
    AssertionError
        Naming the key and the rule it breaks.

    Examples
    --------
    >>> from beatlite.metrics.scoring import METRICS
    >>> check_metric("PCK", METRICS["PCK"], truth_value=1.0, degraded_value=0.4)
    >>> check_metric("PCK", METRICS["PCK"], truth_value=1.0, degraded_value=1.2)
    Traceback (most recent call last):
        ...
    AssertionError: PCK: degraded value 1.2 outside its bounds (0.0, 1.0)
    >>> check_metric("MPJPE", METRICS["MPJPE"], truth_value=0.0, degraded_value=0.0)
    Traceback (most recent call last):
        ...
    AssertionError: MPJPE: the degraded system scores 0.0, as good as perfect 0.0
    """
    _require(metric.describe.strip(), f"{key}: no describe line (what a table caption prints)")
    _require(metric.source.strip(), f"{key}: no source (paper, code or section of the variant)")
    lo, hi = metric.bounds
    for what, value in (("ground-truth", truth_value), ("degraded", degraded_value)):
        _require(math.isfinite(value), f"{key}: {what} value {value} is not finite")
        _require(lo <= value <= hi, f"{key}: {what} value {value} outside its bounds {metric.bounds}")
    if metric.perfect is None:
        return
    _require(
        abs(truth_value - metric.perfect) <= PERFECT_ATOL,
        f"{key}: the ground truth scores {truth_value}, not its perfect value {metric.perfect}",
    )
    if metric.higher_is_better is not None:
        best = hi if metric.higher_is_better else lo
        _require(metric.perfect == best, f"{key}: perfect {metric.perfect} is not the better bound {best}")
        gap = best - degraded_value if metric.higher_is_better else degraded_value - best
        _require(
            gap > PERFECT_ATOL,
            f"{key}: the degraded system scores {degraded_value}, as good as perfect {best}",
        )


def _require(condition: object, message: str) -> None:
    """Raise ``AssertionError(message)`` unless ``condition`` (not ``assert``: it holds under ``python -O``)."""
    if not condition:
        raise AssertionError(message)
