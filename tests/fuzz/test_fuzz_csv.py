"""Fuzz RSSI logs: any text through ``read_rssi_log`` and ``map_log`` gives a map whose samples are
exactly the rows with a position, or one clean error naming the file."""

from __future__ import annotations

import numpy as np
from hypothesis import given
from hypothesis import strategies as st

from sfw_gym.datasets import read_csv
from sfw_gym.mapping.offline import map_log, read_rssi_log
from tests.fuzz.conftest import outcome

numeric = st.integers(-120, 20).map(str) | st.floats(-1e3, 1e3).map(lambda v: f"{v:.2f}")
odd = st.sampled_from(
    ["", " ", "nan", "NA", "inf", "-inf", "1e400", "x", '"-40"', "9" * 50]
) | st.text(alphabet=st.characters(blacklist_categories=["Cs"]), max_size=4)
cells = st.integers(0, 19).flatmap(lambda i: odd if i == 19 else numeric)  # 1 in 20 odd
HEADERS = [
    "x,y,rssi",
    "x_pixel,y_pixel,router1_2.4,router1_5,",
    "x_pixel,y_pixel,router1_2.4,router1_5,router2_2.4,router2_5,",
    "x,y",
    "",
    "a,b,c,d",
]


@st.composite
def logs(draw) -> tuple[str, list[str]]:
    """A header and rows: most as wide as the header (one more for a trailing comma), of
    mostly numeric cells."""
    header = draw(st.sampled_from(HEADERS))
    width = max(1, len(header.split(","))) + draw(st.sampled_from([0, 0, 1]))
    row = st.lists(cells, min_size=width, max_size=width) | st.lists(cells, max_size=8)
    return header, [",".join(r) for r in draw(st.lists(row, max_size=12))]


@given(st.booleans(), logs(), st.sampled_from(["\n", "\r\n"]))
def test_rssi_logs(tmp_path_factory, bom, log_text, newline):
    header, body = log_text
    path = tmp_path_factory.mktemp("csv") / "log.csv"
    text = newline.join([header, *body]) + newline
    path.write_bytes((b"\xef\xbb\xbf" if bom else b"") + text.encode("utf-8", "surrogatepass"))

    def read_and_map() -> None:
        log = read_rssi_log(path)
        assert np.isfinite(log.positions).all() and np.isfinite(log.rssi_dbm).all()
        assert len(log.positions) == len(log.rssi_dbm) == len(log.line_numbers)
        res = map_log(log, [[0.0, 0.0]] * max(1, len(log.rssi_names) // 2), resolution_m=0.5)
        assert res.mapper.n_updates == 2 * log.n_samples  # forward, then reversed

    outcome("RSSI CSV", read_and_map, names="log.csv")


FINGERPRINT_HEADERS = ["x,y,ap1,ap2", "x,y,floor,trajectory,t,ap1", "x,y,x", "y,ap1", "x,y", ""]


@st.composite
def surveys(draw) -> tuple[str, list[list[str]]]:
    """A header and rows, most as wide as the header, of mostly numeric cells."""
    header = draw(st.sampled_from(FINGERPRINT_HEADERS))
    width = max(1, len(header.split(",")))
    row = st.lists(cells, min_size=width, max_size=width) | st.lists(cells, max_size=7)
    return header, draw(st.lists(row, max_size=10))


@given(surveys())
def test_fingerprint_csvs(tmp_path_factory, survey):
    """Any text through the generic fingerprint reader: finite positions and readings (NaN: not
    heard), or one clean error naming the file."""
    header, rows = survey
    path = tmp_path_factory.mktemp("fp") / "survey.csv"
    path.write_text("\n".join([header, *(",".join(r) for r in rows)]) + "\n", encoding="utf-8")

    def read() -> None:
        fp = read_csv(path)
        assert np.isfinite(fp.positions).all() and not np.isinf(fp.rssi_dbm).any()
        assert len(fp) == len(fp.rssi_dbm) > 0

    outcome("fingerprint CSV", read, names="survey.csv")
