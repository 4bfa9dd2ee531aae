"""Fingerprint localisation on real data (issue 38): UJIIndoorLoc train → validation and WiFine
train → val per floor, per scan and tracked along each walk (with and without the floor layouts),
plus a figure of tracked walks on the layout.

    python scripts/benchmarks/bench_fingerprints.py [--datasets ../shared/datasets] [--out bench-fp]

Errors are in each dataset's units: UJIIndoorLoc's Web-Mercator metres (ground ≈ 0.77 ×), as the
literature reports them; WiFine's metres. The tracker's odometry is synthetic (the true positions
plus the drift env's noise, seeded).

Results: docs/results/localization.md#fingerprints-on-real-data; writes
docs/figures/wifine_tracking.png (``--figure``).
"""

from __future__ import annotations

import argparse
import json
import tempfile
from pathlib import Path

import numpy as np

from sfw_gym.datasets import WIFINE_FLOORS, read_ujiindoorloc, read_wifine, write_wifine_maps
from sfw_gym.evaluation.fingerprints import TrackSettings, evaluate
from sfw_gym.world.floorplan import load_floorplan

ROOT = Path(__file__).resolve().parents[2]
UJI_METHODS = ("1nn", "w3nn", "w5nn", "sorensen", "gridmaps")
WIFINE_METHODS = ("1nn", "w3nn", "sorensen", "gridmaps")


def wifine_plans(layouts: Path, folder: Path) -> dict[int | None, object]:
    """The three floors' plans, keyed by floorID, through ROS map YAMLs written in ``folder``."""
    return {k: load_floorplan(path) for k, path in write_wifine_maps(layouts, folder).items()}


def uji_table(root: Path) -> list[str]:
    zip_path = root / "ujiindoorloc" / "UJIIndoorLoc.zip"
    train, test = read_ujiindoorloc(zip_path), read_ujiindoorloc(zip_path, "validation")
    rows = [
        "| method | mean | median | p75 | p95 | floor hit | building hit | fit s | query ms |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for method in UJI_METHODS:
        m, _ = evaluate(train, test, method)
        rows.append(
            f"| {method} | {m['mean_error_m']:.2f} | {m['median_error_m']:.2f} | "
            f"{m['p75_error_m']:.2f} | {m['p95_error_m']:.2f} | "
            f"{100 * m['floor_hit_rate']:.1f} % | {100 * m['building_hit_rate']:.2f} % | "
            f"{m['fit_s']:.1f} | "
            f"{m['query_ms_per_scan']:.2f} |"
        )
        print(rows[-1], flush=True)
    return rows


def per_floor(columns: dict, key: str = "error_m") -> list[float]:
    return [float(np.mean(columns[key][columns["floor_true"] == f])) for f in WIFINE_FLOORS]


def wifine_table(root: Path, plans: dict, out: Path) -> tuple[list[str], dict]:
    train, test = read_wifine(root / "wifine" / "train"), read_wifine(root / "wifine" / "val")
    results: dict[str, list[float]] = {}
    tracks: dict[str, dict] = {}
    for method in WIFINE_METHODS:
        _, columns = evaluate(train, test, method)
        results[f"{method}, per scan"] = per_floor(columns)
        print(method, results[f"{method}, per scan"], flush=True)
    settings = {
        "no layout": TrackSettings(),
        "layout, walls uncrossable": TrackSettings(floorplans=plans),
        "layout, a crossing keeps 10 %": TrackSettings(floorplans=plans, wall_weight=0.1),
    }
    for method in ("sorensen", "gridmaps"):
        for name, track in settings.items():
            metrics, columns = evaluate(train, test, method, track)
            label = f"{method}, tracked, {name}"
            results[label] = per_floor(columns)
            tracks[label] = columns
            (out / f"{method}-{name.replace(' ', '_').replace(',', '')}.json").write_text(
                json.dumps(metrics, indent=2)
            )
            print(label, results[label], flush=True)
    base = results["w3nn, per scan"]
    rows = [
        "| WiFine val | floor 4 | floor 5 | floor 6 | ÷ w3nn per scan (4 / 5 / 6) |",
        "|---|---|---|---|---|",
    ]
    for label, errors in results.items():
        ratios = " / ".join(f"{e / b:.2f}" for e, b in zip(errors, base, strict=True))
        rows.append(f"| {label} | " + " | ".join(f"{e:.2f}" for e in errors) + f" | {ratios} |")
    return rows, tracks


#: What the figure draws of each walk: truth, each scan's own estimate, the track.
TRACES = (
    ("x_true", "y_true", {"color": "k", "lw": 1}, "truth"),
    (
        "per_scan_x",
        "per_scan_y",
        {"color": "tab:orange", "ls": "", "marker": ".", "ms": 3},
        "per scan",
    ),
    ("x", "y", {"color": "tab:blue", "lw": 1.2}, "tracked"),
)


def figure(layouts: Path, columns: dict, path: Path, walks: int = 2) -> None:
    """A few tracked walks per floor over the layout image (0.1 m a pixel, origin bottom-left)."""
    import matplotlib
    from PIL import Image

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 3, figsize=(18, 4.6))
    labels = np.asarray(columns["trajectory"])
    for ax, (floor, name) in zip(axes, WIFINE_FLOORS.items(), strict=True):
        image = np.asarray(Image.open(layouts / f"Floor_{name}_10cm.png"))
        height, width = image.shape[:2]
        ax.imshow(image, extent=(0, width / 10, 0, height / 10), alpha=0.35)
        on_floor = [
            w for w in dict.fromkeys(labels) if np.all(columns["floor_true"][labels == w] == floor)
        ]
        for k, walk in enumerate(on_floor[:walks]):
            rows = np.flatnonzero(labels == walk)
            rows = rows[np.argsort(columns["t"][rows])]
            for x, y, style, label in TRACES:
                ax.plot(
                    columns[x][rows], columns[y][rows], **style, label=label if k == 0 else None
                )
        ax.set_title(f"floor {name}")
        ax.set_aspect("equal")
        ax.axis("off")
    axes[0].legend(loc="lower left", fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=70)
    plt.close(fig)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--datasets", type=Path, default=ROOT.parent / "shared" / "datasets")
    parser.add_argument("--out", type=Path, default=Path("bench-fp"))
    parser.add_argument(
        "--figure", type=Path, default=ROOT / "docs" / "figures" / "wifine_tracking.png"
    )
    parser.add_argument("--skip-uji", action="store_true")
    args = parser.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    lines = []
    if not args.skip_uji:
        lines += [
            "UJIIndoorLoc train → validation (Web-Mercator metres)",
            "",
            *uji_table(args.datasets),
            "",
        ]
    with tempfile.TemporaryDirectory() as tmp:
        plans = wifine_plans(args.datasets / "wifine" / "floor_layouts", Path(tmp))
        rows, tracks = wifine_table(args.datasets, plans, args.out)
        layouts = args.datasets / "wifine" / "floor_layouts"
        figure(layouts, tracks["sorensen, tracked, layout, a crossing keeps 10 %"], args.figure)
    lines += ["WiFine train → val, mean error (m) per floor", "", *rows]
    (args.out / "tables.md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))
    print(f"wrote {args.out / 'tables.md'} and {args.figure}")


if __name__ == "__main__":
    main()
