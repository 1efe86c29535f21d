"""Screenshot of the map page for the README: ``capnav serve MAP`` on a free loopback port, the
system Chromium (headless) asks INSTRUCTION from the robot position ROBOT and saves the page.

    .venv/bin/python scripts/serve_screenshot.py MAP "the pink armchair" -o docs/serve.png [--robot X,Y]
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
from serve.browser import chromium, running_server


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("map", type=Path)
    ap.add_argument("instruction")
    ap.add_argument("-o", "--out", type=Path, default=Path("docs/serve.png"))
    ap.add_argument("--robot", help="X,Y in metres (default: the page's own start)")
    ap.add_argument("--size", default="1400,900", help="window W,H in pixels")
    args = ap.parse_args()
    from selenium.webdriver.common.by import By
    from selenium.webdriver.support import expected_conditions as ec
    from selenium.webdriver.support.ui import WebDriverWait

    w, h = (int(v) for v in args.size.split(","))
    with running_server(args.map) as url, chromium(w, h) as driver:
        driver.get(url + "/")
        wait = WebDriverWait(driver, 60)
        wait.until(lambda d: d.find_element(By.TAG_NAME, "body").get_attribute("data-ready") == "1")
        if args.robot:
            x, y = (float(v) for v in args.robot.split(","))
            driver.execute_script("robot = [arguments[0], arguments[1]]; drawRobot();", x, y)
        driver.find_element(By.ID, "q").send_keys(args.instruction)
        driver.find_element(By.ID, "go").click()
        wait.until(ec.visibility_of_element_located((By.ID, "chosen")))
        wait.until(lambda d: d.execute_script("const i = document.getElementById('chosen-view');"
                                              "return i.hidden || (i.complete && i.naturalWidth > 0);"))
        args.out.parent.mkdir(parents=True, exist_ok=True)
        driver.save_screenshot(str(args.out))
    print(args.out)


if __name__ == "__main__":
    main()
