#!/usr/bin/env python3
"""softsight serve --compare in a real headless browser (chromium + chromium-driver through
python3-selenium): a second video beside the served one, frame by frame at the same position.
The second video is the first's frames from frame 60 on (an image sequence written by the test),
so at position p the second picture must be the first video's frame p + 60: the picture under
blue's true position in frame p + 60 is blue there (and not, where the markers moved, under its
position in frame p), after a seek and after a step. The second run's CSV (`track` on its
images) opened with "compare" gives, at position p, its own frame p, where the truth of frame
p + 60 has the markers, drawn on the second picture.

Every wait is a condition on the page's state checked in the page (Page.wait): no polling.
Exit code 77 (ctest: skipped) when chromium, its driver or selenium is missing.

  serve_compare_browser_test.py --softsight build/src/app/softsight [--screenshot docs/images/serve-compare.png]
"""
import os
import shutil
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from serve_browser_test import (CONFIG, browser_test_main, check, quit_pages,  # noqa: E402
                                render_with_pages, start_serve, stop_server, truth_rows)

OFFSET = 60


def colour(page, canvas, x, y):
    """The [r, g, b] of `canvas` at image point (x, y) (the page's mapping, the zoom included)."""
    return page.state(
        "(() => { const v = document.getElementById('%s'), m = document.getElementById('view');"
        " const [cx, cy] = window.softsight.clientPoint(%f, %f), r = m.getBoundingClientRect();"
        " const d = v.getContext('2d').getImageData(Math.floor((cx - r.left) * v.width / r.width),"
        " Math.floor((cy - r.top) * v.height / r.height), 1, 1).data; return [d[0], d[1], d[2]]; })()"
        % (canvas, x, y))


def is_blue(rgb):
    r, g, b = rgb
    return b > r + 60 and b > g + 30


def run(args, browser, driver):
    import cv2
    folder = tempfile.mkdtemp(prefix="softsight-serve-compare-")
    config = os.path.join(folder, "cfg.yaml")
    video, truth_csv, browsers = render_with_pages(args.softsight, folder, 150, browser, driver, 1)
    page = browsers[0]
    server = None
    try:
        with open(config, "w") as f:
            f.write(CONFIG)
        # The second run: the first's frames from OFFSET on, as an image sequence.
        later = os.path.join(folder, "later")
        os.mkdir(later)
        capture = cv2.VideoCapture(video)
        index = 0
        while True:
            ok, picture = capture.read()
            if not ok:
                break
            if index >= OFFSET:
                cv2.imwrite(os.path.join(later, "%04d.png" % (index - OFFSET)), picture)
            index += 1
        truth = truth_rows(truth_csv)
        server, url = start_serve(args.softsight, ["--input", video, "--config", config, "--compare", later,
                                                         "--port", "0", "--folder", folder])
        page.open(url)
        page.wait("frames on the page, the second video's too",
                  "window.softsight.framesShown >= 5 && window.softsight.compareVideoFrame !== undefined")
        check(page.state("!document.getElementById('view2').hidden && "
                         "document.getElementById('view2').clientWidth === document.getElementById('view').clientWidth"),
              "the second picture is not beside the first at its size")
        page.state("window.softsight.send({type: 'pause'})")
        page.wait("the pause", "window.softsight.status.paused")
        for position, how in ((30, "seek"), (31, "step")):
            if how == "seek":
                page.state("window.softsight.send({type: 'seek', position: %d})" % position)
            else:
                page.click_button("fwd")
            page.wait("position %d in both pictures" % position,
                      "window.softsight.shownPosition === %d && window.softsight.compareVideoFrame === %d"
                      % (position, position))
            now, later_row = truth[position], truth[position + OFFSET]
            moved = ((float(now["blue_x"]) - float(later_row["blue_x"])) ** 2 +
                     (float(now["blue_y"]) - float(later_row["blue_y"])) ** 2) ** 0.5
            check(moved > 20, "blue moved only %.1f px in %d frames: the test cannot tell them apart" % (moved, OFFSET))
            there = colour(page, "view2", float(later_row["blue_x"]), float(later_row["blue_y"]))
            here = colour(page, "view2", float(now["blue_x"]), float(now["blue_y"]))
            first = colour(page, "view", float(now["blue_x"]), float(now["blue_y"]))
            check(is_blue(there) and not is_blue(here) and is_blue(first),
                  "at position %d (%s): the second picture at blue's place in frame %d is %s, at its place in "
                  "frame %d %s; the first picture there %s" % (position, how, position + OFFSET, there, position,
                                                                here, first))
        # The second run's CSV (`track` on its images) opened with "compare": its row at this
        # position is its own frame 31 (the first video's frame 91), blue where the truth of
        # that frame has it, and its markers are drawn on the second picture.
        later_csv = os.path.join(folder, "later.csv")
        subprocess.run([args.softsight, "track", "--input", later, "--config", config, "-o", later_csv],
                       check=True, capture_output=True)
        page.driver.find_element("id", "comparefile").send_keys(later_csv)
        page.wait("the second run's markers drawn", "window.softsight.compare !== null && window.softsight.compareDrawn >= 2")
        other = page.state("window.softsight.compareRow(31)")
        truth_later = truth[31 + OFFSET]
        check(other["frame"] == 31 and other["red_found"] == 1 and other["green_found"] == 1 and
              abs(other["red_x"] - float(truth_later["red_x"])) < 1.5 and
              abs(other["green_y"] - float(truth_later["green_y"])) < 1.5,
              "the second run's row at position 31: %s; the truth of frame %d: %s" % (
                  {k: other.get(k) for k in ("frame", "red_x", "green_y")}, 31 + OFFSET, truth_later))
        # The wheel over the second picture zooms both about the pointer.
        rect = page.state("document.getElementById('view2').getBoundingClientRect().toJSON()")
        page.wheel_at(rect["left"] + rect["width"] / 2, rect["top"] + rect["height"] / 2, -200)
        page.wait("the zoom from the second picture", "window.softsight.zoom().zoom > 1.9")
        if args.screenshot:
            page.driver.save_screenshot(args.screenshot)
    except Exception:
        print("messages: %s\nerrors: %s" % (page.state("window.softsight.messages.slice(-8)"),
                                            page.state("window.softsight.errors.slice(-8)")))
        raise
    finally:
        quit_pages(browsers)
        if server:
            stop_server(server)
    shutil.rmtree(folder)


if __name__ == "__main__":
    sys.exit(browser_test_main(__doc__, run, "serve compare browser test"))
