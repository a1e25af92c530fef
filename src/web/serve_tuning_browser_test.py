#!/usr/bin/env python3
"""softsight serve's tuning in a real headless browser (chromium + chromium-driver through
python3-selenium), on a rendered actuator (`--input synth:bending`, its own config): the mask
view shows the active marker's pixels and each candidate blob's verdict; an HSV slider moved
with the keyboard changes the range (and loses the marker), undo takes it back; a config saved
under a name is listed and loaded back; names that leave the folder, or are not there, are
refused with an error and change nothing.

Every wait is selenium's WebDriverWait on a condition of the page's state (window.softsight).
Exit code 77 (ctest: skipped) when chromium, its driver or selenium is missing.

  serve_tuning_browser_test.py --softsight build/src/app/softsight [--screenshot docs/images/serve-mask.png]
"""
import json
import os
import shutil
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from serve_browser_test import (Page, browser_test_main, check, start_serve, stop_server,  # noqa: E402
                                webdriver_wait)

wait = webdriver_wait


def run(args, browser, driver):
    folder = tempfile.mkdtemp(prefix="softsight-serve-tuning-")
    server, url = start_serve(args.softsight, ["--input", "synth:bending", "--port", "0", "--folder", folder])
    page = None
    try:
        page = Page(browser, driver, url)
        wait(page, "results with red found", "window.softsight.results > 5 && "
             "window.softsight.row(window.softsight.shownFrame) !== null && "
             "window.softsight.row(window.softsight.shownFrame).red_found === 1")
        wait(page, "the folder's configs listed", "(window.softsight.configs || []).includes('synth-bending.yaml')")
        page.click_button("play")  # Pause: every check below is on the frame on screen.
        wait(page, "the pause", "window.softsight.status.paused")
        check(page.state("window.softsight.status.active") == 0, "red is not the active marker")

        # The mask view: red's pixels, its blob chosen, drawn by the page with its verdict.
        page.click_button("maskview")
        wait(page, "the mask view", "window.softsight.status.mask_view && window.softsight.shownMask && "
             "window.softsight.mask.candidates.some(c => c.verdict === 'chosen')")
        wait(page, "the candidates drawn", "window.softsight.candidatesDrawn >= 1")
        if args.screenshot:
            page.driver.save_screenshot(args.screenshot)

        # S lo to its end (255) with the keyboard, as a person would: red is lost on this frame.
        from selenium.webdriver.common.keys import Keys
        undo = page.state("window.softsight.status.undo")
        slider = page.driver.find_element("id", "hsv2")
        slider.send_keys(Keys.END)
        wait(page, "S lo at 255", "window.softsight.status.hsv[2] === 255")
        frame = page.state("window.softsight.shownFrame")
        wait(page, "red lost with S 255-255", "window.softsight.row(%d).red_found === 0 && "
             "!window.softsight.mask.candidates.some(c => c.verdict === 'chosen')" % frame)
        check(page.state("window.softsight.status.undo") == undo + 1, "the range change is not one undo")
        page.driver.find_element("id", "savename").clear()
        page.driver.find_element("id", "savename").send_keys("tuned.yaml")
        page.click_button("save")
        wait(page, "tuned.yaml listed", "(window.softsight.configs || []).includes('tuned.yaml')")
        page.click_button("undo")
        wait(page, "the undo", "window.softsight.status.hsv[2] !== 255 && "
             "window.softsight.row(%d).red_found === 1" % frame)

        # Names from the page: only plain names of files in the folder are loaded.
        errors = page.state("window.softsight.errors.length")
        hsv = page.state("window.softsight.status.hsv")
        for name in ("../tuned.yaml", "/etc/passwd.yaml", "missing.yaml", "tuned.txt"):
            page.state("window.softsight.sendRaw(%s)" % json.dumps(json.dumps({"type": "load", "name": name})))
        bad = ['{"type":"hsv","index":0,"value":180}', '{"type":"hsv","index":7,"value":1}',
               '{"type":"mask_view","on":"yes"}']
        for text in bad:
            page.state("window.softsight.sendRaw(%s)" % json.dumps(text))
        wait(page, "an error for each", "window.softsight.errors.length >= %d" % (errors + 4 + len(bad)))
        check(page.state("window.softsight.status.hsv") == hsv, "a refused message changed the ranges")

        # Loaded back: S lo 255 again.
        from selenium.webdriver.support.ui import Select
        Select(page.driver.find_element("id", "configs")).select_by_value("tuned.yaml")
        page.click_button("load")
        wait(page, "the loaded ranges", "window.softsight.status.hsv[2] === 255")
        page.click_button("maskview")
        wait(page, "the mask view off", "!window.softsight.status.mask_view && !window.softsight.shownMask")
    except Exception:
        if page:
            print("messages: %s\nerrors: %s" % (page.state("window.softsight.messages.slice(-8)"),
                                                page.state("window.softsight.errors.slice(-8)")))
        raise
    finally:
        if page:
            page.quit()
        stop_server(server)
    check(not os.path.exists(os.path.join(os.path.dirname(folder), "tuned.yaml")), "a file left the folder")
    shutil.rmtree(folder)


if __name__ == "__main__":
    sys.exit(browser_test_main(__doc__, run, "serve tuning browser test"))
