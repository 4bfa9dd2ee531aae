"""Opens a report's ``index.html`` in headless Chromium and checks what a reader sees.

Every image must have loaded (decoded, non-zero size), no request may fail and the console must
show no error; ``--screenshot`` saves the top of the page as a PNG (the docs' first page shows the
demo's). Needs Playwright (the ``test`` extra) and a Chromium: ``--chromium`` or the first of
``chromium``, ``chromium-browser``, ``google-chrome`` on the PATH.

    sfw-gym demo --out runs/demo
    python scripts/tools/check_report.py runs/demo/index.html \
        --screenshot docs/figures/demo_report.png   # the docs' first page shows it
"""

from __future__ import annotations

import argparse
import shutil
import sys
from dataclasses import dataclass, field
from pathlib import Path

BROWSERS = ("chromium", "chromium-browser", "google-chrome")
#: The screenshot's viewport: a laptop's browser window.
VIEWPORT = {"width": 1280, "height": 900}


@dataclass
class PageCheck:
    """What the browser saw: the images (src → loaded), failed requests, console errors."""

    images: dict[str, bool] = field(default_factory=dict)
    failed_requests: list[str] = field(default_factory=list)
    console_errors: list[str] = field(default_factory=list)

    @property
    def problems(self) -> list[str]:
        broken = [f"image not loaded: {src}" for src, ok in self.images.items() if not ok]
        failed = [f"request failed: {r}" for r in self.failed_requests]
        return broken + failed + [f"console: {e}" for e in self.console_errors]


def find_chromium() -> str | None:
    """The path of a Chromium on the PATH, or None."""
    return next((path for name in BROWSERS if (path := shutil.which(name))), None)


def check_page(index: Path, chromium: str, screenshot: Path | None = None) -> PageCheck:
    """Load ``index`` (a file) in headless ``chromium``; optionally save a screenshot."""
    from playwright.sync_api import sync_playwright

    check = PageCheck()
    with sync_playwright() as pw:
        browser = pw.chromium.launch(executable_path=chromium, args=["--no-sandbox"])
        try:
            page = browser.new_page(viewport=VIEWPORT)  # type: ignore[arg-type]
            page.on(
                "console",
                lambda msg: check.console_errors.append(msg.text) if msg.type == "error" else None,
            )
            page.on("pageerror", lambda exc: check.console_errors.append(str(exc)))
            page.on("requestfailed", lambda req: check.failed_requests.append(req.url))
            page.goto(index.resolve().as_uri(), wait_until="load")
            check.images = page.evaluate(
                "() => Object.fromEntries([...document.images].map("
                "i => [i.getAttribute('src'), i.complete && i.naturalWidth > 0]))"
            )
            if screenshot is not None:
                screenshot.parent.mkdir(parents=True, exist_ok=True)
                page.screenshot(path=str(screenshot))
        finally:
            browser.close()
    return check


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("index", type=Path, help="the report's index.html")
    parser.add_argument("--screenshot", type=Path, help="save the top of the page as this PNG")
    parser.add_argument("--chromium", help="the browser's executable (default: found on PATH)")
    args = parser.parse_args(argv)
    if not args.index.is_file():
        parser.error(f"{args.index}: no such file")
    chromium = args.chromium or find_chromium()
    if chromium is None:
        parser.error(f"no Chromium on the PATH (looked for {', '.join(BROWSERS)}); use --chromium")
    check = check_page(args.index, chromium, args.screenshot)
    print(f"{args.index}: {sum(check.images.values())}/{len(check.images)} images loaded")
    for problem in check.problems:
        print(problem, file=sys.stderr)
    return 1 if check.problems else 0


if __name__ == "__main__":
    sys.exit(main())
