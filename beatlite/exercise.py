"""Exercises in the notebooks: run a student's function, fall back to the reference, check the answer.

Each exercise in a notebook is a pair of cells: a stub the student fills in
(its body raises ``NotImplementedError``) followed by a call to :func:`check`,
and a ``solution`` cell (tagged ``solution``; instructors keep it, the student
copy made by ``make run`` in ``build/student/`` drops it). :func:`resolve`
lets later cells keep working while the exercise is not done yet, so every
notebook still runs end to end.

Used by the Exercises section at the end of every notebook (first in notebooks/00_setup_and_tour.ipynb, Exercises).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np


def resolve(student_fn: Callable[..., Any], reference_fn: Callable[..., Any]) -> Callable[..., Any]:
    """Return a function that calls ``student_fn`` and falls back to ``reference_fn``.

    When the student's function raises ``NotImplementedError`` a one-line
    message says so and the reference result is returned instead.
    """

    def call(*args: Any, **kwargs: Any) -> Any:
        try:
            return student_fn(*args, **kwargs)
        except NotImplementedError:
            name = getattr(student_fn, "__name__", "exercise")
            print(f"[exercise] {name} not done yet: using the reference implementation")
            return reference_fn(*args, **kwargs)

    return call


def check(
    name: str,
    student_fn: Callable[..., Any],
    reference_fn: Callable[..., Any],
    cases: list[tuple[tuple, dict]] | list[tuple],
    *,
    rtol: float = 1e-5,
    atol: float = 1e-8,
) -> bool | None:
    """Compare a student's function with the reference on fixed inputs.

    Parameters
    ----------
    name : str
        Exercise name shown in the message.
    student_fn, reference_fn : callable
        The student's function and beatlite's reference.
    cases : list
        Inputs, each ``(args, kwargs)`` or a plain ``args`` tuple.
    rtol, atol : float
        Tolerances of ``numpy.allclose`` for numeric results.

    Returns
    -------
    bool or None
        True when every case matches, False when one does not, None when the
        exercise is not done yet. Never raises for a wrong answer: it prints a hint.
    """
    for i, case in enumerate(cases):
        args, kwargs = case if (len(case) == 2 and isinstance(case[1], dict)) else (case, {})
        try:
            got = student_fn(*args, **kwargs)
        except NotImplementedError:
            print(f"[exercise] {name}: not done yet (the stub raises NotImplementedError)")
            return None
        want = reference_fn(*args, **kwargs)
        try:
            ok = bool(
                np.allclose(np.asarray(got, dtype=float), np.asarray(want, dtype=float), rtol=rtol, atol=atol)
            )
        except (TypeError, ValueError):
            ok = got == want
        if not ok:
            print(f"[exercise] {name}: case {i} differs: got {got!r}, expected {want!r}")
            return False
    print(f"[exercise] {name}: correct on {len(cases)} cases ✓")
    return True
