"""An append-only array: O(1) amortised appends, O(1) read-only views of everything so far."""

from __future__ import annotations

import numpy as np


class AppendOnlyArray:
    """Rows of a fixed width appended one at a time; :attr:`view` is read-only and copies nothing.

    Capacity doubles when full, so ``n`` appends cost O(n) in all. A view taken earlier keeps
    showing the rows that existed when it was taken (appends never write into them).

    Args:
        width: Values per row.
        dtype: Element type.
        capacity: Rows allocated up front.
    """

    def __init__(self, width: int, dtype: type | np.dtype = np.float64, capacity: int = 1024):
        self._data = np.empty((max(1, capacity), width), dtype)
        self._n = 0

    def append(self, row: np.ndarray | tuple[float, ...]) -> None:
        """Add one row (anything that broadcasts to ``(width,)``)."""
        if self._n == len(self._data):
            self.reserve(self._n + 1)
        self._data[self._n] = row
        self._n += 1

    def reserve(self, rows: int) -> None:
        """Make room for ``rows`` rows in all (doubling the capacity as often as needed)."""
        capacity = len(self._data)
        if rows > capacity:
            while capacity < rows:
                capacity *= 2
            grown = np.empty((capacity, self._data.shape[1]), self._data.dtype)
            grown[: self._n] = self._data[: self._n]
            self._data = grown

    def __len__(self) -> int:
        return self._n

    @property
    def view(self) -> np.ndarray:
        """The ``(n, width)`` rows so far, read-only, without copying."""
        out = self._data[: self._n]
        out.flags.writeable = False
        return out
