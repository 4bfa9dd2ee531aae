"""What rebuilding the belief map along a corrected trajectory needs: the mapper as it was every
``every`` updates (pickled) and the bump of every step."""

from __future__ import annotations

import pickle

from sfw_gym.mapping import SparseInverseKVisibility


class MapHistory:
    """Mapper snapshots every ``every`` steps and each step's bump flag."""

    def __init__(self, every: int) -> None:
        self.every = every
        self.bumps: list[bool] = []
        self._snapshots: dict[int, bytes] = {}

    def record(self, step: int, mapper: SparseInverseKVisibility, bumped: bool) -> None:
        """Call before the mapper takes the reading of a new step ``step`` (from 0)."""
        self.snapshot(step, mapper)
        self.bumps.append(bool(bumped))

    def snapshot(self, step: int, mapper: SparseInverseKVisibility) -> None:
        """Keep the mapper as it is before step ``step``'s reading, every ``every`` steps."""
        if step % self.every == 0:
            self._snapshots[step] = pickle.dumps(mapper, protocol=pickle.HIGHEST_PROTOCOL)

    def restore(self, step: int) -> tuple[SparseInverseKVisibility, int]:
        """The mapper as it was before the latest snapshot at or before ``step``, and that
        snapshot's step; the later snapshots are dropped (a replay takes them again)."""
        start = max(s for s in self._snapshots if s <= step)
        for later in [s for s in self._snapshots if s > start]:
            del self._snapshots[later]
        return pickle.loads(self._snapshots[start]), start
