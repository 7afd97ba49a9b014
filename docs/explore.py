"""Regenerate docs/explore.png: the page of `rollingtop explore examples/fig5.toml --look roller`
in Debian's chromium (headless), at C2 = -1.6, h = 3.6 (before the fold: two centres and a
saddle), after a click on the phase portrait has started a trajectory (its path, rotation class
and the roller device's last frame beside it).
Run: python docs/explore.py   (needs the explore extra and `apt-get install chromium`)"""

import os
import shutil
import signal
from pathlib import Path

from playwright.sync_api import sync_playwright

from rollingtop.explore.server import CHROMIUM_FLAGS, spawn

if __name__ == "__main__":
    examples = Path(__file__).parents[1] / "examples"
    browser = os.environ.get("ROLLINGTOP_BROWSER") or shutil.which("chromium")
    if browser is None:
        raise SystemExit("no chromium: apt-get install chromium (or set ROLLINGTOP_BROWSER)")
    proc, url = spawn(str(examples / "fig5.toml"), args=("--look", "roller"))
    try:
        with sync_playwright() as p:
            b = p.chromium.launch(executable_path=browser, args=list(CHROMIUM_FLAGS))
            page = b.new_page(viewport={"width": 1340, "height": 760})
            page.goto(url + "?C2=-1.6&h=3.6")
            page.get_by_text("steady motions:").first.wait_for(timeout=60_000)
            page.wait_for_timeout(1000)
            box = page.locator(".bk-Canvas").nth(0).bounding_box()
            page.mouse.click(box["x"] + 0.3 * box["width"], box["y"] + 0.62 * box["height"])
            page.get_by_text("trajectory: t = 0").first.wait_for(timeout=30_000)
            page.wait_for_timeout(3000)  # the device's frame is drawn after the path
            out = Path(__file__).with_name("explore.png")
            page.screenshot(path=str(out))
            b.close()
        print(f"wrote {out}")
    finally:
        proc.send_signal(signal.SIGINT)
        proc.wait(timeout=15)
