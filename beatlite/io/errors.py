"""Errors raised by the readers of :mod:`beatlite.io`.

Not taught in a notebook; ``docs/architecture.md`` (Conventions) states the error contract.
"""

from __future__ import annotations

from pathlib import Path


class FormatError(ValueError):
    """A file does not follow the format its reader expects.

    The message always names the file and, where it can, the line, column or
    field that is wrong, e.g. ``take.bvh, line 433, column 17: 'abc' is not a
    number``.

    Parameters
    ----------
    path : str or Path or None
        File being read (``None`` for in-memory text).
    message : str
        What is wrong.
    line : int, optional
        1-based line number.
    column : int, optional
        1-based column (token) number.
    field : str, optional
        Name of the field (JSON key, CSV column, ...).

    Examples
    --------
    >>> err = FormatError("take.bvh", "'abc' is not a number", line=433, column=17)
    >>> str(err)
    "take.bvh, line 433, column 17: 'abc' is not a number"
    >>> isinstance(err, ValueError)
    True
    """

    def __init__(
        self,
        path: str | Path | None,
        message: str,
        *,
        line: int | None = None,
        column: int | None = None,
        field: str | None = None,
    ) -> None:
        self.path = None if path is None else Path(path)
        self.line = line
        self.column = column
        self.field = field
        self.reason = message
        where = [str(self.path) if self.path is not None else "<text>"]
        if line is not None:
            where.append(f"line {line}")
        if column is not None:
            where.append(f"column {column}")
        if field is not None:
            where.append(f"field {field!r}")
        super().__init__(f"{', '.join(where)}: {message}")

    def __reduce__(self) -> tuple:
        """Pickle by the constructor's arguments, so the error crosses process boundaries (worker pools)."""
        kwargs = {"line": self.line, "column": self.column, "field": self.field}
        return (_format_error, (self.path, self.reason, kwargs))


def _format_error(path: Path | None, reason: str, kwargs: dict) -> FormatError:
    return FormatError(path, reason, **kwargs)


class FormatWarning(UserWarning):
    """A file is readable but inconsistent (truncated audio, annotation times that disagree, ...).

    The message names the file and what was assumed.

    Examples
    --------
    >>> import warnings
    >>> with warnings.catch_warnings(record=True) as caught:
    ...     warnings.simplefilter("always")
    ...     warnings.warn("take.wav: truncated, 100 of 200 frames", FormatWarning)
    >>> caught[0].category.__name__, issubclass(FormatWarning, UserWarning)
    ('FormatWarning', True)
    """


class BVHWarning(FormatWarning):
    """A BVH file is readable but inconsistent, e.g. ``Frames: 100`` above 99 motion rows.

    Examples
    --------
    >>> issubclass(BVHWarning, FormatWarning)
    True
    """


class AlignmentWarning(UserWarning):
    """The modalities of a take have different durations and were truncated to the shortest.

    Examples
    --------
    >>> import warnings
    >>> with warnings.catch_warnings(record=True) as caught:
    ...     warnings.simplefilter("always")
    ...     warnings.warn("audio 14.8 s, motion 14.6 s: truncated to 14.6 s", AlignmentWarning)
    >>> caught[0].category.__name__, issubclass(AlignmentWarning, UserWarning)
    ('AlignmentWarning', True)
    """
