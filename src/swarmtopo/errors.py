"""User-facing errors.

Every error a user can cause with bad input is a :class:`SwarmtopoError`; the CLI
prints it as one line and exits non-zero.  :class:`InputError` quotes the data: the
file, the row, the column, the bad value and what was expected.
"""

from __future__ import annotations


class SwarmtopoError(Exception):
    """An error caused by the user's input or request, reported as one line."""


class InputError(SwarmtopoError, ValueError):
    """Bad input data, located as precisely as the caller knows.

    Parameters
    ----------
    message
        What is wrong and what was expected.
    file, row, column, value
        Where: the file (or logical source) name, the 1-based data row, the column
        name and the offending value.  Each is optional.
    """

    def __init__(self, message: str, *, file=None, row=None, column=None, value=None):
        self.file, self.row, self.column, self.value = file, row, column, value
        self.reason = message
        where = []
        if file is not None:
            where.append(str(file))
        if row is not None:
            where.append(f"row {row}")
        if column is not None:
            where.append(f"column '{column}'")
        if value is not None:
            where.append(f"value {_short(value)!r}")
        prefix = ", ".join(where)
        super().__init__(f"{prefix}: {message}" if prefix else message)


class ArenaError(InputError):
    """Invalid arena geometry."""


def _short(value, limit: int = 80):
    text = str(value)
    return text if len(text) <= limit else text[: limit - 3] + "..."
