"""Take the README's picture of the monitor, ``docs/images/monitor_map.png``.

Runs ``cyborg up`` (this checkout's, for 40 s, without the camera and detector) on free ports,
opens its monitor in Debian's Chromium at 1400x900 with Playwright (the page's defaults: the
tree at its readable size), waits until the robot has moved on its patrol and is on its way
along a drawn path, and saves the page. Run
``python3 scripts/monitor_map_screenshot.py [OUT.png]`` after changing how the page looks.
"""

from __future__ import annotations

import os
import shutil
import socket
import subprocess
import sys
import time
from pathlib import Path

from playwright.sync_api import sync_playwright

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "docs" / "images" / "monitor_map.png"
ROBOT = "/cyborg"
ON_ITS_WAY = f"""(() => {{
    const m = window.__map, r = m && m.robot({ROBOT!r});
    return Boolean(r && r.state === 'MOVING_TO_GOAL' && r.pathShown && r.toGo > 6
                   && m.moving.paths > 1 && m.moving.laser > 100);
}})()"""


def free_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        port: int = probe.getsockname()[1]
        return port


def wait_for_port(port: int, timeout: float) -> None:
    deadline = time.monotonic() + timeout
    while True:
        try:
            socket.create_connection(("127.0.0.1", port), 0.5).close()
            return
        except OSError:
            if time.monotonic() > deadline:
                raise
            time.sleep(0.2)


def main(out: Path) -> None:
    web, bus = free_port(), free_port()
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(
        [str(ROOT / "src"), *filter(None, [os.environ.get("PYTHONPATH")])])}
    up = subprocess.Popen(["timeout", "-s", "INT", "40", sys.executable, "-m", "cyborg", "up",
                           "--monitor-port", str(web), "--listen", f"tcp/127.0.0.1:{bus}",
                           "--no-detector"], env=env, stdout=subprocess.DEVNULL)
    try:
        wait_for_port(web, 20)
        chromium = shutil.which("chromium") or shutil.which("chromium-browser")
        with sync_playwright() as playwright:
            browser = playwright.chromium.launch(executable_path=chromium,
                                                 args=["--disable-gpu", "--disable-quic"])
            page = browser.new_page(viewport={"width": 1400, "height": 900})
            page.goto(f"http://127.0.0.1:{web}/")
            page.wait_for_function(f"window.__map && window.__map.firstPaint !== null && "
                                   f"window.__map.robot({ROBOT!r})?.pose", timeout=20000)
            start = page.evaluate(f"window.__map.robot({ROBOT!r}).pose")
            page.wait_for_function(f"(() => {{ const p = window.__map.robot({ROBOT!r}).pose; "
                                   f"return Math.hypot(p.x - {start['x']}, p.y - {start['y']})"
                                   " > 1.5; })()", timeout=25000)
            for _ in range(40):  # the page as it was while the robot was on its way
                page.wait_for_function(ON_ITS_WAY, timeout=20000)
                page.screenshot(path=str(out))
                if page.evaluate(ON_ITS_WAY):
                    break
            browser.close()
    finally:
        up.wait(60)
    print(f"wrote {out} ({out.stat().st_size:,} bytes)")


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else OUT)
