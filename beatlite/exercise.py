"""Exercises in the notebooks: run a student's function, fall back to the reference, check the answer.

Each exercise in a notebook is a pair of cells: a stub the student fills in
(its body raises ``NotImplementedError``) followed by a call to :func:`check`,
and a ``solution`` cell (tagged ``solution``; instructors keep it, the student
copy made by ``make run`` in ``build/student/`` drops it). :func:`resolve`
lets later cells keep working while the exercise is not done yet, so every
notebook still runs end to end.

The feedback of :func:`check` names the failing case (numbered from 1) with its
inputs, then the first thing that differs: a missing ``return``, the type, the
shape, the kind of dtype (integer, float, bool), or the first differing element
(index, both values, how many elements differ). It never prints whole arrays.

"Why?" questions get feedback too: :func:`choice` checks a multiple-choice answer
against a key that does not show the answer, and :func:`predict` compares a number
the student predicted with the value the next lines measure, within exactly the
tolerance the cell gives.

How the keys of :func:`choice` hide the answer: a key is the first 12 hex digits of
``sha256(salt | question | answer)``, and the salt is the course's, not the
student's: it is never printed or passed in a notebook cell, and :func:`answer_key`
does not know it (the salt is its required third argument). So the options and the
key in a student's cell do not give the answer away, neither read nor recomputed
with ``answer_key(question, option)``. The instructor makes a key with
``python scripts/instructor_sheet.py --key QUESTION ANSWER``, and
``scripts/instructor_sheet.py`` (run by ``make run``) writes every exercise's solution,
choice and "why?" answer to ``build/instructor/``. This keeps answers out of sight,
not secret: the salt is in this module (``_SALT``), ``notebooks/`` holds the
solutions, and trying every option with :func:`choice` is always possible; a
student who does that learns less, not more. A key that depends on the data (the
answer changes with the corpus) is made in the library by the function that poses
the question (e.g. :func:`beatlite.models.ha2g_losses.costliest_pair_question`),
never by a computation in the student's cell.

Examples
--------
>>> def double(x):
...     return x + x
>>> check("square", double, lambda x: x * x, [(2,), (3,)])
[exercise] square: case 2 of 2 differs: square(3)
    got 6, expected 9
False

Used by the Exercises section at the end of every notebook (first in notebooks/00_setup_and_tour.ipynb, Exercises).
"""

from __future__ import annotations

import copy
import functools
import hashlib
import numbers
from collections.abc import Callable, Mapping
from typing import Any

import numpy as np

_KINDS = {"b": "bool", "i": "integer", "u": "integer", "f": "float", "c": "complex"}


def resolve(student_fn: Callable[..., Any], reference_fn: Callable[..., Any]) -> Callable[..., Any]:
    """Return a function that calls ``student_fn`` and falls back to ``reference_fn``.

    When the student's function raises ``NotImplementedError`` a one-line
    message says so and the reference result is returned instead.

    Examples
    --------
    A stub not filled in yet gives the reference's answer (with the message); once done, its own:

    >>> def mean_speed(x):
    ...     raise NotImplementedError
    >>> speed = resolve(mean_speed, lambda x: sum(x) / len(x))
    >>> speed([1.0, 2.0, 6.0])
    [exercise] mean_speed not done yet: using the reference implementation
    3.0
    >>> speed.__name__  # the student's function's name and docstring stay
    'mean_speed'
    >>> def mean_speed(x):
    ...     return max(x)  # a wrong answer is the student's to see: resolve does not check it
    >>> resolve(mean_speed, lambda x: sum(x) / len(x))([1.0, 2.0, 6.0])
    6.0
    """

    @functools.wraps(student_fn)
    def call(*args: Any, **kwargs: Any) -> Any:
        try:
            return student_fn(*args, **kwargs)
        except NotImplementedError:
            name = getattr(student_fn, "__name__", "exercise")
            print(f"[exercise] {name} not done yet: using the reference implementation")
            return reference_fn(*args, **kwargs)

    return call


def describe(value: Any, width: int = 60) -> str:
    """A short description of an input or a result: small values in full, big arrays by shape and dtype.

    Examples
    --------
    >>> describe(np.zeros((20, 5, 3)))
    'array(shape=(20, 5, 3), dtype=float64)'
    >>> describe(np.array([1.5, 2.0]))
    'array([1.5, 2. ])'
    >>> describe(0.1 + 0.2)
    '0.3'
    """
    if isinstance(value, np.ndarray) and value.size <= 6:
        return "array(" + np.array2string(value, precision=4, separator=", ") + ")"
    if hasattr(value, "shape") and hasattr(value, "dtype") and np.ndim(value) > 0:
        dtype = str(value.dtype).removeprefix("torch.")
        return (
            f"{type(value).__name__.replace('ndarray', 'array')}(shape={tuple(value.shape)}, dtype={dtype})"
        )
    if isinstance(value, numbers.Real) and not isinstance(value, numbers.Integral | bool):
        text = f"{float(value):.6g}"
        return text if any(c in text for c in ".en") else text + ".0"  # 15.0 stays a float
    if isinstance(value, list | tuple) and len(value) > 6:
        return f"{type(value).__name__} of {len(value)} items: {describe(value[0], width // 2)}, ..."
    text = repr(value)
    return text if len(text) <= width else text[: width - 3] + "..."


def _call_text(name: str, args: tuple, kwargs: dict) -> str:
    parts = [describe(a) for a in args] + [f"{k}={describe(v)}" for k, v in kwargs.items()]
    return f"{name}({', '.join(parts)})"


def difference(got: Any, want: Any, *, rtol: float = 1e-5, atol: float = 1e-8) -> str | None:
    """Why ``got`` is not ``want`` in one line, or ``None`` when they match (``numpy.isclose``, NaN == NaN).

    For float32 (or float16) arrays, ``atol`` grows by what rounding alone may change: 16 units in the last place
    of the largest finite ``|want|`` at that precision (float32: ``16 * 1.19e-7 * max|want|``), so that a solution
    summing in another order than the reference (numpy's einsum against torch) matches on elements near zero.
    Torch tensors (also inside a list or tuple) are compared as their values: detached from autograd, on the CPU;
    a bfloat16 one within bfloat16's rounding of each element (``rtol`` at least ``2**-8``: the exact answer
    rounded to bfloat16 matches, one computed in bfloat16 may not).

    Examples
    --------
    >>> difference(None, 4.5)
    'got None: does the function end with `return ...`?'
    >>> difference(np.zeros(3), np.zeros(4))
    'shape: got (3,), expected (4,)'
    >>> difference(np.array([1.0, 2.0, 3.0]), np.array([1.0, 2.5, 3.5]))
    'first difference at index (1,): got 2.0, expected 2.5 (2 of 3 elements differ)'
    >>> difference((np.zeros(2), np.ones(3)), (np.zeros(2), np.zeros(3)))  # items of other shapes: one by one
    'item 1: first difference at index (0,): got 1.0, expected 0.0 (3 of 3 elements differ)'
    """
    if got is None and want is not None:
        return "got None: does the function end with `return ...`?"
    try:
        (g, g_eps, g_rtol), (w, w_eps, w_rtol) = _values(got), _values(want)
    except (TypeError, ValueError):  # ragged containers: item by item
        if isinstance(got, list | tuple) and isinstance(want, list | tuple):
            if len(got) != len(want):
                return f"length: got {len(got)} items, expected {len(want)}"
            why = ((i, difference(a, b, rtol=rtol, atol=atol)) for i, (a, b) in enumerate(zip(got, want)))
            return next((f"item {i}: {d}" for i, d in why if d is not None), None)
        return None if _equal(got, want) else f"got {describe(got)}, expected {describe(want)}"
    if g.dtype == object or w.dtype == object or g.dtype.kind in "USV" or w.dtype.kind in "USV":
        return None if _equal(got, want) else f"got {describe(got)}, expected {describe(want)}"
    if g.shape != w.shape:
        return f"shape: got {g.shape}, expected {w.shape}"
    if g.ndim and _KINDS.get(g.dtype.kind) != _KINDS.get(w.dtype.kind):
        return f"dtype: got {_KINDS.get(g.dtype.kind, g.dtype)} ({g.dtype}), expected {_KINDS.get(w.dtype.kind, w.dtype)} ({w.dtype})"
    atol, rtol = atol + _rounding(w, max(g_eps, w_eps)), max(rtol, g_rtol, w_rtol)
    kind = complex if "c" in (g.dtype.kind, w.dtype.kind) else float  # (float would drop imaginary parts)
    close = np.isclose(g.astype(kind), w.astype(kind), rtol=rtol, atol=atol, equal_nan=True)
    if close.all():
        return None
    if g.ndim == 0:
        return f"got {describe(got)}, expected {describe(want)}"
    first = np.unravel_index(int(np.argmin(close)), close.shape)
    index = tuple(int(i) for i in first)
    return (
        f"first difference at index {index}: got {describe(g[index].item())}, expected {describe(w[index].item())} "
        f"({int((~close).sum())} of {close.size} elements differ)"
    )


def _values(x: Any) -> tuple[np.ndarray, float, float]:
    """``x`` as a numpy array, the machine epsilon of its float type (0.0 for integers and others) and the least
    ``rtol`` its precision allows (0.0 but for bfloat16, which numpy lacks: read as float32, its ``2**-8``); torch
    tensors detached and on the CPU, also in a list or tuple."""
    if _is_tensor(x):
        import torch

        t = x.detach()
        if t.dtype == torch.bfloat16:
            return t.float().numpy(force=True), 0.0, 2.0**-8
        return t.numpy(force=True), (torch.finfo(t.dtype).eps if t.is_floating_point() else 0.0), 0.0
    if isinstance(x, list | tuple) and any(_is_tensor(e) for e in x):
        parts = [_values(e) for e in x]
        return np.asarray([a for a, _, _ in parts]), max(e for _, e, _ in parts), max(r for _, _, r in parts)
    a = np.asarray(x)
    return a, (float(np.finfo(a.dtype).eps) if a.dtype.kind == "f" else 0.0), 0.0


def _is_tensor(x: Any) -> bool:
    return hasattr(x, "detach") and hasattr(x, "dtype") and hasattr(x, "is_floating_point")


def _rounding(want: np.ndarray, eps: float) -> float:
    """16 units in the last place of ``max |want|`` at the precision of epsilon ``eps``, the lower of the two
    arrays' (0 for float64 and integers): how far two orders of the same float32 sums may fall apart."""
    if eps <= np.finfo(np.float64).eps:
        return 0.0
    finite = np.abs(want[np.isfinite(want)]) if want.dtype.kind in "fc" else np.abs(want)
    return float(16 * eps * finite.max()) if finite.size else 0.0


def _equal(got: Any, want: Any) -> bool:
    try:
        return bool(got == want)
    # arrays (numpy's ValueError) or tensors (torch's RuntimeError) inside a container
    except (ValueError, RuntimeError):
        return False


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
        Tolerances of ``numpy.isclose`` for numeric results.

    Returns
    -------
    bool or None
        True when every case matches, False when one does not, None when the
        exercise is not done yet. A wrong answer prints the case (numbered from 1)
        with its inputs and :func:`difference`'s line; an exception raised by the
        student's function is re-raised after the same case line. Each function gets
        its own copy of the inputs (:func:`copy.deepcopy`), so a function that changes
        its arguments in place changes neither the other's inputs nor the notebook's
        variables.

    Examples
    --------
    >>> def shift(x):
    ...     x -= x.mean()  # in place: the caller's array would change
    ...     return x
    >>> data = np.array([1.0, 2.0, 6.0])
    >>> check("shift", shift, lambda x: x - x.mean(), [(data,)]), data
    [exercise] shift: correct on 1 cases ✓
    (True, array([1., 2., 6.]))
    """
    for i, case in enumerate(cases, start=1):
        args, kwargs = case if (len(case) == 2 and isinstance(case[1], dict)) else (case, {})
        where = f"case {i} of {len(cases)}"
        try:
            got = student_fn(*_copied(args), **_copied(kwargs))
        except NotImplementedError:
            print(f"[exercise] {name}: not done yet (the stub raises NotImplementedError)")
            return None
        except Exception as exc:
            print(f"[exercise] {name}: {where} raised {type(exc).__name__}: {_call_text(name, args, kwargs)}")
            raise
        why = difference(got, reference_fn(*_copied(args), **_copied(kwargs)), rtol=rtol, atol=atol)
        if why is not None:
            print(f"[exercise] {name}: {where} differs: {_call_text(name, args, kwargs)}\n    {why}")
            return False
    print(f"[exercise] {name}: correct on {len(cases)} cases ✓")
    return True


def _copied(values: Any) -> Any:
    """A deep copy of a case's arguments (the objects themselves where one cannot be copied)."""
    try:
        return copy.deepcopy(values)
    except Exception:  # noqa: BLE001 - e.g. a handle to a file: passed as it is
        return values


#: The course's salt for :func:`choice` keys (see the module docstring: it keeps answers out of sight, not secret).
_SALT = "beatlite-course-2026|b7c1f0e2"


def answer_key(name: str, answer: Any, salt: str) -> str:
    """The 12-hex-digit key of ``answer`` to question ``name`` under ``salt``, for :func:`choice`.

    A notebook's key is made with the course's salt (instructors: ``scripts/instructor_sheet.py --key``), which
    no notebook cell shows, so a key cannot be recomputed from the question and its options alone. Answers
    are compared stripped and case-insensitive.

    Examples
    --------
    >>> answer_key("05 indicator bit", "B", salt="my class")
    '68d0c02f0849'
    >>> answer_key("05 indicator bit", " b ", salt="my class") == answer_key("05 indicator bit", "B", salt="my class")
    True
    >>> answer_key("05 indicator bit", "b", salt="another class")
    '6d8ebe3a62a0'
    """
    text = f"{salt}|beatlite-exercise|{name}|{str(answer).strip().lower()}"
    return hashlib.sha256(text.encode()).hexdigest()[:12]


def course_key(name: str, answer: Any) -> str:
    """:func:`answer_key` with the course's salt: for the library functions that pose a question on measured data.

    Not for notebook cells (a call in a student's cell would show the answer it is given).

    Examples
    --------
    >>> course_key("seed bit", "b") == answer_key("seed bit", "b", _SALT) != answer_key("seed bit", "b", "")
    True
    """
    return answer_key(name, answer, _SALT)


def choice(name: str, answer: Any, options: Mapping[str, str], key: str, *, hint: str = "") -> bool | None:
    """Check a multiple-choice answer to a "why?" question.

    Parameters
    ----------
    name : str
        The question's name (part of the key).
    answer : str or None
        The student's choice, one of ``options`` (case-insensitive); ``None`` while unanswered.
    options : mapping
        Choice -> statement, printed while unanswered.
    key : str
        ``answer_key(name, correct_choice, salt)`` with the course's salt (:func:`course_key`); the cell holds
        only the key, so it never shows the right choice.
    hint : str
        Printed after a wrong choice; it should point at the evidence, not at the answer.

    Returns
    -------
    bool or None
        True (right), False (wrong or not an option), None (not answered yet).

    Examples
    --------
    >>> options = {"a": "it trains faster", "b": "a seed pose can be all zeros"}
    >>> key = course_key("seed bit", "b")  # instructors: scripts/instructor_sheet.py --key "seed bit" b
    >>> choice("seed bit", "a", options, key, hint="What does a 0 input mean?")
    [exercise] seed bit: a is not the best answer. What does a 0 input mean?
    False
    >>> choice("seed bit", "b", options, key)
    [exercise] seed bit: b is right ✓
    True
    """
    valid = {str(k).strip().lower(): k for k in options}
    if not any(course_key(name, k) == key for k in valid):
        raise ValueError(f"choice {name!r}: the key {key!r} matches none of the options {list(options)}")
    if answer is None:
        lines = [f"[exercise] {name}: not answered yet; set the answer to one of:"]
        lines += [f"    {k}: {text}" for k, text in options.items()]
        print("\n".join(lines))
        return None
    if str(answer).strip().lower() not in valid:
        print(f"[exercise] {name}: {answer!r} is not one of the options {list(options)}")
        return False
    if course_key(name, answer) == key:
        print(f"[exercise] {name}: {answer} is right ✓")
        return True
    print(f"[exercise] {name}: {answer} is not the best answer. {hint}".rstrip())
    return False


def predict(
    name: str,
    guess: float | None,
    actual: float,
    *,
    rtol: float | None = None,
    atol: float | None = None,
    unit: str = "",
) -> bool | None:
    """Compare a numeric prediction, written down before running the code, with the measured value.

    Parameters
    ----------
    name : str
        What was predicted.
    guess : float or None
        The student's prediction; ``None`` while not made.
    actual : float
        The value the notebook measured (same unit as ``guess``).
    rtol, atol : float or None
        The prediction counts as right when ``|guess - actual| <= atol + rtol * |actual|``. A tolerance given
        is the whole tolerance: when only one of the two is given the other is 0; when neither is given,
        ``rtol=0.1`` (within 10 %) and ``atol=0``.
    unit : str
        Unit printed after the numbers.

    Returns
    -------
    bool or None
        True (within tolerance), False (outside; the message says how far, in which direction, and the
        tolerance), None (no prediction made: the measured value is not shown, so the student can still predict).

    Examples
    --------
    >>> predict("mel frames per 34-pose window", 68, 70, rtol=0.05)  # 70: notebook 03; 5 % of 70 = 3.5
    [exercise] mel frames per 34-pose window: predicted 68, measured 70 ✓
    True

    Only the tolerance given counts: ``atol=5`` is 5 samples, with no 10 % of 36,545 (3,654.5 samples) added:

    >>> predict("audio for 35 frames", 36266, 36545, atol=5, unit="samples")  # 36266 samples give 34 frames
    [exercise] audio for 35 frames: predicted 36266 samples, measured 36545 samples: too low by 279 samples (within ±5 samples counts as right)
    False
    >>> predict("audio for 35 frames", 36545, 36545, atol=5, unit="samples")
    [exercise] audio for 35 frames: predicted 36545 samples, measured 36545 samples ✓
    True
    """
    if rtol is None and atol is None:
        rtol, atol = 0.1, 0.0
    rtol, atol = float(rtol or 0.0), float(atol or 0.0)
    if rtol < 0 or atol < 0:
        raise ValueError(f"predict {name!r}: tolerances must be >= 0, got rtol={rtol}, atol={atol}")
    if guess is None:
        print(f"[exercise] {name}: write your prediction first (the measured value is printed afterwards)")
        return None
    guess, actual = float(guess), float(actual)
    unit = f" {unit}" if unit else ""
    tolerance = atol + rtol * abs(actual)
    if abs(guess - actual) <= tolerance:
        print(f"[exercise] {name}: predicted {guess:.6g}{unit}, measured {actual:.6g}{unit} ✓")
        return True
    side = "high" if guess > actual else "low"
    gap = f" by {abs(guess - actual):.3g}{unit}"
    far = actual != 0 and guess != 0 and abs(guess / actual - 1) >= 0.1  # a ratio near 1 would print as "1x"
    ratio = f", {abs(guess / actual):.2g}x the measured value" if far else ""
    print(
        f"[exercise] {name}: predicted {guess:.6g}{unit}, measured {actual:.6g}{unit}: too {side}{gap}{ratio} "
        f"(within ±{tolerance:.3g}{unit} counts as right)"
    )
    return False
