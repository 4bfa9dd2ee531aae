"""``sfw-gym evaluate --backend ray``: the same records as the local backend (where Ray is
installed: ``pip install "sfw-gym[ray]"``), and a clear error where it is not."""

from __future__ import annotations

import importlib.util
import json

import pytest

from sfw_gym.cli import main
from sfw_gym.evaluation import evaluate

HAS_RAY = importlib.util.find_spec("ray") is not None
RUN = dict(env_id="SfW-ExploreSmall-v0", env_kwargs={"max_steps": 60}, progress=False)


@pytest.mark.skipif(HAS_RAY, reason="Ray is installed here")
def test_without_ray_the_backend_is_one_line_naming_the_extra(tmp_path, capsys):
    argv = ["evaluate", "--agents", "frontier", "--episodes", "1", "--backend", "ray"]
    assert main([*argv, "--out", str(tmp_path)]) == 2
    assert "pip install 'sfw-gym[ray]'" in capsys.readouterr().err


@pytest.mark.skipif(not HAS_RAY, reason="needs Ray (pip install 'sfw-gym[ray]')")
def test_ray_gives_the_local_backends_records(tmp_path):
    local = evaluate(["frontier", "random"], 3, 7, out=tmp_path / "local", workers=2, **RUN)
    ray = evaluate(
        ["frontier", "random"], 3, 7, out=tmp_path / "ray", workers=2, backend="ray", **RUN
    )

    def keyed(result):
        return {
            r["key"]: json.dumps({k: v for k, v in r.items() if k not in ("wall_s", "steps_per_s")})
            for r in result["records"]
        }

    assert keyed(ray) == keyed(local)
    assert (tmp_path / "ray" / "results.md").read_text() == (
        tmp_path / "local" / "results.md"
    ).read_text()
