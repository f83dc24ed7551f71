"""Open a recording in rerun's web viewer, in headless Chromium, and check what it shows.

    python scripts/check_rerun_viewer.py FILE.rrd SCREENSHOT.png [--wait 30] [--json]

Serves FILE.rrd with ``rerun --serve-web`` on free local ports, opens the viewer in Debian's
``chromium`` driven by Playwright (software WebGL: ``--use-angle=swiftshader
--enable-unsafe-swiftshader``), waits (``--wait`` s, default 30) and takes a screenshot. Then it
reads the screenshot's pixels (envs.viewer_check.analyse) and prints what it found:
  loaded       the viewer got past its loading screen (enough distinct, non-background pixels)
  body         the body view (the left column of the blueprint) shows the biped's link colours
  footfalls    the footfall panel shows both feet's lane colours
Exit status 0 when all three hold, 1 otherwise, 2 on bad input or a missing browser.
"""
from __future__ import annotations

import argparse
import contextlib
import json
import os
import shutil
import socket
import subprocess
import sys
import time

CHROMIUM = "/usr/bin/chromium"
ARGS = ["--no-sandbox", "--use-angle=swiftshader", "--enable-unsafe-swiftshader",
        "--disable-background-networking", "--disable-component-update", "--disable-sync",
        "--no-first-run", "--disable-dev-shm-usage"]


def free_port() -> int:
    with contextlib.closing(socket.socket()) as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def wait_for_port(port: int, timeout: float) -> bool:
    end = time.time() + timeout
    while time.time() < end:
        with contextlib.closing(socket.socket()) as s:
            if s.connect_ex(("127.0.0.1", port)) == 0:
                return True
        time.sleep(0.2)
    return False


def screenshot(rrd: str, png: str, wait_s: float = 30.0, width: int = 1600,
               height: int = 1000) -> None:
    """Serve ``rrd`` in rerun's web viewer and save a screenshot of it after ``wait_s``."""
    from playwright.sync_api import sync_playwright

    web, grpc = free_port(), free_port()
    rerun = shutil.which("rerun") or os.path.join(os.path.dirname(sys.executable), "rerun")
    # Its own process group: the `rerun` launcher starts the native viewer as a child, and
    # both must go when we are done.
    server = subprocess.Popen([rerun, "--serve-web", "--web-viewer-port", str(web), "--port",
                               str(grpc), rrd], stdout=subprocess.DEVNULL,
                              stderr=subprocess.DEVNULL, start_new_session=True)
    try:
        if not (wait_for_port(web, 30) and wait_for_port(grpc, 30)):
            raise RuntimeError("rerun's web viewer did not start")
        url = (f"http://127.0.0.1:{web}/?url=rerun%2Bhttp%3A%2F%2F127.0.0.1%3A{grpc}"
               f"%2Fproxy")
        with sync_playwright() as p:
            browser = p.chromium.launch(executable_path=CHROMIUM, args=ARGS)
            page = browser.new_page(viewport={"width": width, "height": height})
            page.goto(url)
            time.sleep(wait_s)
            page.screenshot(path=png)
            browser.close()
    finally:
        import signal

        try:
            os.killpg(server.pid, signal.SIGTERM)
            server.wait(timeout=10)
        except (ProcessLookupError, subprocess.TimeoutExpired):
            with contextlib.suppress(ProcessLookupError):
                os.killpg(server.pid, signal.SIGKILL)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("rrd")
    ap.add_argument("png")
    ap.add_argument("--wait", type=float, default=30.0)
    ap.add_argument("--json", action="store_true")
    a = ap.parse_args(argv)
    if not os.path.isfile(a.rrd) or not a.rrd.endswith(".rrd"):
        print(f"check_rerun_viewer: error: {a.rrd!r} is not an .rrd file", file=sys.stderr)
        return 2
    if not os.path.exists(CHROMIUM):
        print(f"check_rerun_viewer: error: {CHROMIUM} is missing (apt-get install chromium)",
              file=sys.stderr)
        return 2
    from cpgbiped.envs.media.viewer_check import analyse

    screenshot(a.rrd, a.png, a.wait)
    res = analyse(a.png)
    print(json.dumps(res, indent=2) if a.json else
          "\n".join(f"{k}: {v}" for k, v in res.items()))
    return 0 if res["loaded"] and res["body"] and res["footfalls"] else 1


if __name__ == "__main__":
    raise SystemExit(main())
