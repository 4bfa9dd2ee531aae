"""``sfw-gym localize``: the study runs end to end and writes its tables and figures."""

from __future__ import annotations

import json

import pytest

from sfw_gym.cli import main


@pytest.mark.slow
def test_the_localization_study_writes_every_table_and_figure(tmp_path, capsys):
    out = tmp_path / "loc"
    argv = ["localize", "--plans", "1", "--runs", "1", "--survey-steps", "300"]
    argv += ["--test-steps", "60", "--particles", "100", "--workers", "1", "--out", str(out)]
    assert main(argv) == 0
    tables = (out / "tables.md").read_text()
    assert capsys.readouterr().out.startswith(tables.splitlines()[0])
    for row in ("| GP | direct |", "| mGP | gridmaps |", "| uint8 |", "| 0.1 |", "| 5.0 |"):
        assert row in tables
    results = json.loads((out / "results.json").read_text())
    speed = results["summary"]["update_ms_1000"]
    assert speed["direct"] > speed["gridmaps"] > 0  # a lookup beats a GP prediction
    assert {r["table"] for r in results["plans"][0]["rows"]} == {"I", "II", "III", "kidnap"}
    assert (out / "gridmaps.png").stat().st_size > 10_000
    assert (out / "error_over_time.png").stat().st_size > 10_000


def test_json_is_the_old_name_of_out(tmp_path):
    from sfw_gym.cli import build_parser

    args = build_parser().parse_args(["localize", "--json", str(tmp_path / "study")])
    assert args.out == str(tmp_path / "study")


def test_an_output_path_that_is_a_file_is_refused(tmp_path, capsys):
    (tmp_path / "f").write_text("x")
    for option in ("--out", "--json"):  # --json: the old name, an alias
        with pytest.raises(SystemExit) as exc:
            main(["localize", option, str(tmp_path / "f")])
        assert exc.value.code == 2
        assert "f" in capsys.readouterr().err
