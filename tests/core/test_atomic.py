"""Atomic writes: a file or folder appears whole or not at all, and what a killed writer left
behind is cleared on resume."""

from __future__ import annotations

import pytest

from sfw_gym.core.atomic import atomic_dir, atomic_path, remove_stale_temps


def test_a_folder_appears_whole_or_not_at_all(tmp_path):
    with atomic_dir(tmp_path / "ckpt") as tmp:
        (tmp / "weights.bin").write_bytes(b"1234")
        assert not (tmp_path / "ckpt").exists()  # only once the block ends
    assert (tmp_path / "ckpt" / "weights.bin").read_bytes() == b"1234"
    with pytest.raises(RuntimeError), atomic_dir(tmp_path / "broken") as tmp:
        (tmp / "half").write_text("x")
        raise RuntimeError("killed mid-write")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["ckpt"]


def test_stale_temporary_files_and_folders_are_removed(tmp_path):
    with atomic_path(tmp_path / "model.zip") as tmp:
        tmp.write_text("done")
    stale_file = tmp_path / ".results.abc.tmp.json"
    stale_file.write_text("half")
    stale_dir = tmp_path / "checkpoints" / ".iter_000003.xyz.tmp"
    stale_dir.mkdir(parents=True)
    (stale_dir / "part").write_text("half")
    removed = remove_stale_temps(tmp_path)
    assert set(removed) == {stale_file, stale_dir}
    assert not stale_file.exists() and not stale_dir.exists()
    assert (tmp_path / "model.zip").read_text() == "done"
