#!/usr/bin/env python3
"""softsight serve's tuning and analysis tools in a real headless browser (chromium + chromium-driver through
python3-selenium), on a rendered actuator (`--input synth:bending`, its own config): the mask
view shows the active marker's pixels and each candidate blob's verdict; an HSV slider moved
with the keyboard changes the range (and loses the marker), undo takes it back; a config saved
under a name is listed and loaded back; names that leave the folder, or are not there, are
refused with an error and change nothing; the angle and distance tools measure what the
tracker's own columns say, and a click on a trail seeks to that frame.

Every wait is a condition on the page's state (window.softsight) checked in the page on every
message and redraw (Page.wait): no polling. The server and the browser start at once.
Exit code 77 (ctest: skipped) when chromium, its driver or selenium is missing.

  serve_tuning_browser_test.py --softsight build/src/app/softsight [--screenshot docs/images/serve-mask.png]
"""
import json
import os
import shutil
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from serve_browser_test import (browser_test_main, check, serve_with_pages, stop_server,  # noqa: E402
                                webdriver_wait)

wait = webdriver_wait


def test_analysis(page, screenshot=None):
    """An angle on red, blue and green clicked on the picture is the row's angle; a distance from
    red to green is its chord in mm; both are plot lanes and CSV columns. With the trails shown, a
    click on green's path where it was in another frame seeks there."""
    # Played on into the bend (a trail to click, an angle well off straight) at 4x, then paused.
    from selenium.webdriver.support.ui import Select
    Select(page.driver.find_element("id", "speed")).select_by_value("4")
    wait(page, "4x", "window.softsight.status.speed === 4")
    page.click_button("play")
    wait(page, "the bend", "window.softsight.status.position >= 110")
    page.click_button("play")
    wait(page, "the pause", "window.softsight.status.paused && "
         "window.softsight.shownPosition === window.softsight.status.position && "
         "window.softsight.row(window.softsight.shownFrame) !== null")
    frame = page.state("window.softsight.shownFrame")
    row = page.state("window.softsight.row(%d)" % frame)
    for tool, names in (("toolangle", ("red", "blue", "green")), ("tooldistance", ("red", "green"))):
        page.click_button(tool)
        for name in names:
            page.click_image_point(row[name + "_x"], row[name + "_y"])
    wait(page, "two tools", "window.softsight.tools.length === 2")
    angle = page.state("window.softsight.toolValue(0, %d)" % frame)
    distance = page.state("window.softsight.toolValue(1, %d)" % frame)
    check(abs(angle - row["angle_deg"]) < 0.01, "the angle tool: %s, the row's angle %s" % (angle, row["angle_deg"]))
    check(abs(distance - row["chord_mm"]) < 0.005 * row["chord_mm"],
          "the distance tool: %s mm, the row's chord %s mm" % (distance, row["chord_mm"]))
    header = page.state("window.softsight.csvText()").splitlines()[0].split(",")
    check(header[-2:] == ["angle_red_blue_green_deg", "distance_red_green_mm"], "the CSV's last columns: %s" % header[-3:])
    check(len(page.state("window.softsight.toolLanes()")) == 2, "the tools are not plotted")
    test_fixed_point_dragged(page, frame, row)
    page.click_button("trails")
    wait(page, "the trails drawn", "window.softsight.trailPoints > 10")
    if screenshot:
        page.driver.save_screenshot(screenshot)
    # Where green was farthest from where it is now: a click there seeks to that frame.
    rows = page.state("window.softsight.rowsIn().filter(r => r.green_found === 1 && r._position >= 0)")
    far = max(rows, key=lambda r: (r["green_x"] - row["green_x"]) ** 2 + (r["green_y"] - row["green_y"]) ** 2)
    page.click_image_point(far["green_x"], far["green_y"])
    wait(page, "the seek from the trail", "window.softsight.shownPosition !== %d && "
         "window.softsight.row(window.softsight.shownFrame) !== null" % row["_position"])
    landed = page.state("window.softsight.row(window.softsight.shownFrame)")
    check(((landed["green_x"] - far["green_x"]) ** 2 + (landed["green_y"] - far["green_y"]) ** 2) ** 0.5 < 6,
          "the trail click landed on frame %d, green at (%.1f, %.1f), not near (%.1f, %.1f)" % (
              landed["frame"], landed["green_x"], landed["green_y"], far["green_x"], far["green_y"]))


def test_fixed_point_dragged(page, frame, row):
    """A distance from red to a fixed point away from every marker; that point dragged onto
    green's place: the distance is then red to green, the row's chord (mm); the drag moved the
    point, not a box (no reselection: the undo depth is unchanged)."""
    spot = (row["red_x"] + 80, row["red_y"] + 40)
    page.click_button("tooldistance")
    page.click_image_point(row["red_x"], row["red_y"])
    page.click_image_point(*spot)
    wait(page, "the third tool", "window.softsight.tools.length === 3")
    check(page.state("window.softsight.tools[2].points.map(p => p.marker || null)") == ["red", None],
          "not a distance from red to a fixed point: %s" % page.state("window.softsight.tools[2].points"))
    undo = page.state("window.softsight.status.undo")
    x0, y0 = page.state("window.softsight.clientPoint(%f, %f)" % spot)
    x1, y1 = page.state("window.softsight.clientPoint(%f, %f)" % (row["green_x"], row["green_y"]))
    page.drag(x0, y0, x1, y1)
    wait(page, "the fixed point on green", "Math.hypot(window.softsight.tools[2].points[1].x - %f, "
         "window.softsight.tools[2].points[1].y - %f) < 1" % (row["green_x"], row["green_y"]))
    distance = page.state("window.softsight.toolValue(2, %d)" % frame)
    check(abs(distance - row["chord_mm"]) < 0.005 * row["chord_mm"],
          "the dragged distance: %s mm, the row's chord %s mm" % (distance, row["chord_mm"]))
    check(page.state("window.softsight.status.undo") == undo, "the drag reselected a marker")


def run(args, browser, driver):
    folder = tempfile.mkdtemp(prefix="softsight-serve-tuning-")
    # The server and the browser start at once.
    server, url, (page,) = serve_with_pages(
        args.softsight, ["--input", "synth:bending", "--port", "0", "--folder", folder], browser, driver, 1)
    try:
        page.open(url)
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
        # And the scene's own config back: red found again.
        Select(page.driver.find_element("id", "configs")).select_by_value("synth-bending.yaml")
        page.click_button("load")
        wait(page, "the scene's ranges back", "window.softsight.status.hsv[2] !== 255 && "
             "window.softsight.row(window.softsight.shownFrame).red_found === 1")
        test_analysis(page, args.screenshot and args.screenshot.replace(".png", "-analysis.png"))
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
