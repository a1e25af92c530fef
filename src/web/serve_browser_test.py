#!/usr/bin/env python3
"""softsight serve in a real headless browser (Debian's chromium + chromium-driver, driven by
python3-selenium): the page loads, frames and results arrive, a click picks a colour, a seek
lands on the frame, hostile messages are refused and change nothing, a wrong token is refused,
a second browser sees the same run read-only, the server survives 100 connections opened and
dropped, a dragged box sets a template, and a recording made from the page reproduces under
`softsight track`. Measures the latency from capture to the picture on the page (640x480, 30 fps).

Every wait on the page is a condition on its state (window.softsight) checked in the page on every
message and redraw (Page.wait), with a timeout: no polling, and no sleep decides a result. The
browsers start while the video renders.
Exit code 77 (ctest: skipped) only when chromium or its driver or selenium is missing.

  serve_browser_test.py --softsight build/src/app/softsight [--screenshot docs/images/serve.png]
"""
import argparse
import csv
import json
import os
import re
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import time
import urllib.error
import urllib.request

SKIP = 77
CONFIG = """\
markers:
  - {name: red,   hsv: {h: [170, 10], s: [80, 255], v: [40, 255]}}
  # Wrong on purpose (a yellow range): blue is not found until the page picks its colour.
  - {name: blue,  hsv: {h: [20, 30], s: [80, 255], v: [40, 255]}}
  - {name: green, hsv: {h: [45, 85], s: [80, 255], v: [40, 255]}}
triple: [red, blue, green]
"""


def find_chromium():
    try:
        from selenium import webdriver  # noqa: F401
    except ImportError:
        return None, "python3-selenium is not installed"
    for browser in ("/usr/bin/chromium", shutil.which("chromium") or ""):
        if browser and os.path.exists(browser):
            driver = shutil.which("chromedriver") or "/usr/bin/chromedriver"
            if os.path.exists(driver):
                return (browser, driver), None
            return None, "chromium-driver is not installed"
    return None, "chromium is not installed"


def wait_for(what, condition, timeout=15.0, interval=0.05):
    """Polls `condition` until it returns something true; fails naming `what` after `timeout`."""
    deadline = time.monotonic() + timeout
    while True:
        value = condition()
        if value:
            return value
        if time.monotonic() > deadline:
            raise AssertionError("timed out waiting for " + what)
        time.sleep(interval)


def check(condition, message):
    if not condition:
        raise AssertionError(message)


def webdriver_wait(page, what, expression, timeout=10.0, details="window.softsight.status"):
    """Waits until the page's `expression` is true (Page.wait: checked in the page on every
    message and redraw, no polling); fails naming `what` and showing the page's `details`."""
    return page.wait(what, expression, timeout, details)


def stop_server(server):
    """SIGINT, as Ctrl-C: the server must end within 20 s with exit code 130. Its output."""
    server.send_signal(signal.SIGINT)
    try:
        out, err = server.communicate(timeout=20)
    except subprocess.TimeoutExpired:
        server.kill()
        raise AssertionError("serve did not stop on SIGINT")
    check(server.returncode == 130, "serve exited %d after SIGINT: %s" % (server.returncode, err))
    return out, err


def browser_test_main(doc, run, what):
    """The command line of each browser test: --softsight, --screenshot; 77 when the browser,
    its driver or selenium is missing."""
    parser = argparse.ArgumentParser(description=doc.splitlines()[0])
    parser.add_argument("--softsight", required=True)
    parser.add_argument("--screenshot", help="write the page's screenshot (PNG) here")
    args = parser.parse_args()
    found, why = find_chromium()
    if not found:
        print("SKIPPED: %s (scripts/setup.sh installs chromium, chromium-driver, python3-selenium)" % why)
        return SKIP
    started = time.monotonic()
    run(args, *found)
    print("%s passed in %.1f s" % (what, time.monotonic() - started))
    return 0


class Page:
    """A headless chromium. `url` None: started only (open() it later), so that browsers start
    while the video renders and the server starts (start_pages)."""
    def __init__(self, browser, driver_path, url=None):
        from selenium import webdriver
        from selenium.webdriver.chrome.service import Service
        options = webdriver.ChromeOptions()
        options.binary_location = browser
        for flag in ("--headless=new", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage",
                     "--window-size=1500,1150", "--force-device-scale-factor=1"):
            options.add_argument(flag)
        # The page is on this computer: no proxy from the environment in between.
        options.add_argument("--no-proxy-server")
        self.driver = webdriver.Chrome(service=Service(driver_path), options=options)
        if url:
            self.open(url)

    def open(self, url):
        self.driver.get(url)

    def state(self, expression):
        return self.driver.execute_script("return " + expression)

    def wait(self, what, expression, timeout=15.0, details="window.softsight.status"):
        """The first true value of the page's `expression`, checked in the page at once and after
        every message and redraw it handles (softsight.when): no polling, no sleep. Fails after
        `timeout` naming `what`, with the page's `details` and its last errors."""
        self.driver.set_script_timeout(timeout + 10)
        value = self.driver.execute_async_script(
            "const done = arguments[arguments.length - 1];"
            "const wait = () => window.softsight.when(() => (%s), %d).then((v) => done(v === undefined ? null : v));"
            # Before the page's script has run (just opened): once it has.
            "if (window.softsight && window.softsight.when) wait();"
            "else window.addEventListener('load', wait);" % (expression, int(timeout * 1000)))
        if not value:
            raise AssertionError("timed out waiting for %s (%s): %s; errors on the page: %s" % (
                what, expression, self.state(details), self.state("window.softsight.errors.slice(-4)")))
        return value

    def click_at(self, x, y):
        from selenium.webdriver.common.action_chains import ActionChains
        actions = ActionChains(self.driver)
        actions.w3c_actions.pointer_action.move_to_location(int(round(x)), int(round(y)))
        actions.w3c_actions.pointer_action.click()
        actions.perform()

    def drag(self, x0, y0, x1, y1):
        from selenium.webdriver.common.action_chains import ActionChains
        actions = ActionChains(self.driver)
        pointer = actions.w3c_actions.pointer_action
        pointer.move_to_location(int(round(x0)), int(round(y0)))
        pointer.pointer_down()
        pointer.move_to_location(int(round((x0 + x1) / 2)), int(round((y0 + y1) / 2)))
        pointer.move_to_location(int(round(x1)), int(round(y1)))
        pointer.pointer_up()
        actions.perform()

    def wheel_at(self, x, y, delta_y):
        """The mouse wheel over viewport point (x, y): negative `delta_y` scrolls up (zooms in)."""
        from selenium.webdriver.common.action_chains import ActionChains
        from selenium.webdriver.common.actions.wheel_input import ScrollOrigin
        ActionChains(self.driver).scroll_from_origin(
            ScrollOrigin.from_viewport(int(round(x)), int(round(y))), 0, int(delta_y)).perform()

    def right_drag(self, x0, y0, x1, y1):
        from selenium.webdriver.common.action_chains import ActionChains
        from selenium.webdriver.common.actions.mouse_button import MouseButton
        actions = ActionChains(self.driver)
        pointer = actions.w3c_actions.pointer_action
        pointer.move_to_location(int(round(x0)), int(round(y0)))
        pointer.pointer_down(button=MouseButton.RIGHT)
        pointer.move_to_location(int(round((x0 + x1) / 2)), int(round((y0 + y1) / 2)))
        pointer.move_to_location(int(round(x1)), int(round(y1)))
        pointer.pointer_up(button=MouseButton.RIGHT)
        actions.perform()

    def view_colour(self, x, y):
        """The picture's [r, g, b] on screen at viewport point (x, y), read from the canvas."""
        return self.state(
            "(() => { const v = document.getElementById('view'), r = v.getBoundingClientRect();"
            " const d = v.getContext('2d').getImageData(Math.floor((%f - r.left) * v.width / r.width),"
            " Math.floor((%f - r.top) * v.height / r.height), 1, 1).data; return [d[0], d[1], d[2]]; })()"
            % (x, y))

    def click_image_point(self, x, y):
        cx, cy = self.state("window.softsight.clientPoint(%f, %f)" % (x, y))
        self.click_at(cx, cy)

    def click_button(self, element_id):
        self.driver.find_element("id", element_id).click()

    def quit(self):
        """Idempotent: a test may quit a page early (a page that leaves)."""
        if self.driver is not None:
            self.driver.quit()
            self.driver = None


def start_pages(browser, driver, count):
    """`count` browsers started at once, each in its own thread (a browser takes ~2 s to start,
    mostly waiting): not yet on a page."""
    import concurrent.futures
    with concurrent.futures.ThreadPoolExecutor(count) as pool:
        return list(pool.map(lambda _: Page(browser, driver), range(count)))


def render_with_pages(softsight, folder, frames, browser, driver, count):
    """The bending scene rendered to FOLDER/run.avi (640x480, 30 fps, `frames` frames) with its
    truth (FOLDER/truth.csv), while `count` browsers start (each takes seconds, mostly waiting):
    (video, truth_csv, pages not yet opened). Nothing left running when one of them fails."""
    video, truth_csv = os.path.join(folder, "run.avi"), os.path.join(folder, "truth.csv")
    synth = subprocess.Popen([softsight, "synth", "--scene", "bending", "--frames", str(frames), "--size",
                              "640x480", "--fps", "30", "-o", video, "--truth", truth_csv],
                             stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    browsers = []
    try:
        browsers = start_pages(browser, driver, count)
        _, err = synth.communicate(timeout=60)
        check(synth.returncode == 0, "synth failed: %s" % err)
    except BaseException:
        synth.kill()
        quit_pages(browsers)
        raise
    return video, truth_csv, browsers


def quit_pages(pages):
    """Every browser quit at once (each takes a few hundred ms)."""
    import concurrent.futures
    with concurrent.futures.ThreadPoolExecutor(max(1, len(pages))) as pool:
        list(pool.map(lambda page: page.quit(), pages))


def serve_with_pages(softsight, arguments, browser, driver, count):
    """`softsight serve ARGUMENTS` and `count` browsers, started at once: (server, url, pages),
    the pages not yet opened. Nothing left running when one of them fails."""
    import concurrent.futures
    with concurrent.futures.ThreadPoolExecutor(1) as pool:
        browsers = pool.submit(start_pages, browser, driver, count)
        try:
            server, url = start_serve(softsight, arguments)
        except BaseException:
            quit_pages(browsers.result())
            raise
        try:
            return server, url, browsers.result()
        except BaseException:
            server.kill()
            raise


def start_serve(softsight, arguments):
    """`softsight serve ARGUMENTS` and the page's URL it prints (after what it says of a rig)."""
    server = subprocess.Popen([softsight, "serve"] + arguments, stdout=subprocess.PIPE,
                              stderr=subprocess.PIPE, text=True)
    lines = []
    for _ in range(5):
        lines.append(server.stdout.readline())
        match = re.search(r"open (http://\S+)", lines[-1])
        if match:
            return server, match.group(1).replace("HOST", "127.0.0.1")
    server.kill()
    raise AssertionError("serve printed no URL: %r %s" % (lines, server.stderr.read()))


def start_server(softsight, folder, video, config):
    return start_serve(softsight, ["--input", video, "--config", config, "--bind", "0.0.0.0",
                                   "--port", "0", "--folder", folder])


def http_status(url):
    # Straight to the server: a proxy from the environment must not answer for it.
    opener = urllib.request.build_opener(urllib.request.ProxyHandler({}))
    try:
        with opener.open(url, timeout=5) as response:
            return response.status
    except urllib.error.HTTPError as error:
        return error.code


def websocket_handshake_status(port, target):
    with socket.create_connection(("127.0.0.1", port), timeout=5) as sock:
        sock.sendall(("GET %s HTTP/1.1\r\nHost: 127.0.0.1:%d\r\nUpgrade: websocket\r\n"
                      "Connection: Upgrade\r\nSec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\n"
                      "Sec-WebSocket-Version: 13\r\n\r\n" % (target, port)).encode())
        status_line = sock.recv(4096).split(b"\r\n", 1)[0].decode()
        return int(status_line.split()[1])


def open_and_drop(port, count, token):
    kinds = [b"", b"GET / HTT", ("GET /ws?token=%s HTTP/1.1\r\nHost: 127.0.0.1:%d\r\nUpgrade: "
             "websocket\r\nConnection: Upgrade\r\nSec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\n"
             "Sec-WebSocket-Version: 13\r\n\r\n" % (token, port)).encode(), b"\xff" * 3000]
    for i in range(count):
        sock = socket.create_connection(("127.0.0.1", port), timeout=5)
        if kinds[i % 4]:
            sock.sendall(kinds[i % 4])
        sock.close()


def truth_rows(path):
    with open(path) as f:
        return {int(row["frame"]): row for row in csv.DictReader(f)}


def assert_near_truth(row, truth, names, tolerance=1.5):
    for name in names:
        check(row.get(name + "_found") == 1, "%s not found in frame %s" % (name, row.get("frame")))
        dx = row[name + "_x"] - float(truth[name + "_x"])
        dy = row[name + "_y"] - float(truth[name + "_y"])
        check((dx * dx + dy * dy) ** 0.5 < tolerance,
              "%s at (%.2f, %.2f), truth (%s, %s)" % (name, row[name + "_x"], row[name + "_y"],
                                                       truth[name + "_x"], truth[name + "_y"]))


def latency_figures(page):
    # The first frames include the page's start (decoder warm-up); the run's own are after.
    # The browser runs on the server's computer: one clock, no offset to estimate.
    samples = sorted(page.state("window.softsight.sameClockLatencies.slice(10)"))
    check(len(samples) >= 30, "only %d latency samples" % len(samples))
    median = samples[len(samples) // 2]
    p95 = samples[int(len(samples) * 0.95)]
    return median, p95, len(samples)


def in_ranges(hsv, ranges):
    """True when the OpenCV HSV pixel lies in the six ranges (a hue range with lo > hi wraps)."""
    h, s, v = hsv
    hue = ranges[0] <= h <= ranges[1] if ranges[0] <= ranges[1] else (h >= ranges[0] or h <= ranges[1])
    return hue and ranges[2] <= s <= ranges[3] and ranges[4] <= v <= ranges[5]


def test_mask_click_grows(page, video, blue):
    """In the mask view of blue (its range yellow on purpose: none of its pixels), a click on
    blue widens the ranges to take in the pixel clicked (its HSV read from the video with
    OpenCV, not from the page); a shift-click there takes it out again; two undos put the yellow
    range back, each saying what it undid."""
    import cv2
    page.click_button("maskview")
    page.wait("the mask view", "window.softsight.status.mask_view && window.softsight.shownMask === true")
    before = page.state("window.softsight.status.hsv")
    undo = page.state("window.softsight.status.undo")
    position = page.state("window.softsight.shownPosition")
    cx, cy = (round(v) for v in page.state("window.softsight.clientPoint(%s, %s)" % (blue["blue_x"], blue["blue_y"])))
    x, y = (int(round(v)) for v in page.state("window.softsight.imagePoint(%d, %d)" % (cx, cy)))
    capture = cv2.VideoCapture(video)
    capture.set(cv2.CAP_PROP_POS_FRAMES, position)
    ok, picture = capture.read()
    check(ok, "OpenCV did not read frame %d of the video" % position)
    pixel = [int(c) for c in cv2.cvtColor(picture[y:y + 1, x:x + 1], cv2.COLOR_BGR2HSV)[0, 0]]
    check(not in_ranges(pixel, before), "blue's pixel %s is in the yellow range %s already" % (pixel, before))
    page.click_at(cx, cy)
    page.wait("the range edit", "window.softsight.status.undo === %d" % (undo + 1))
    grown = page.state("window.softsight.status.hsv")
    check(in_ranges(pixel, grown), "the clicked pixel (HSV %s) is not in the grown ranges %s" % (pixel, grown))
    # A shift-click there takes those colours out again: the pixel is no member any more.
    from selenium.webdriver.common.action_chains import ActionChains
    from selenium.webdriver.common.keys import Keys
    actions = ActionChains(page.driver)
    actions.key_down(Keys.SHIFT)
    # Each pointer step with a pause of the keyboard beside it: the shift stays down until the
    # button is up (the two devices step together, one action each per tick).
    pointer, keys = actions.w3c_actions.pointer_action, actions.w3c_actions.key_action
    pointer.move_to_location(cx, cy)
    keys.pause(0)
    pointer.pointer_down()
    keys.pause(0)
    pointer.pointer_up()
    keys.pause(0)
    actions.key_up(Keys.SHIFT)
    actions.perform()
    page.wait("the shift-click's edit", "window.softsight.status.undo === %d" % (undo + 2))
    shrunk = page.state("window.softsight.status.hsv")
    check(not in_ranges(pixel, shrunk), "the shift-clicked pixel (HSV %s) is still in %s" % (pixel, shrunk))
    page.click_button("undo")
    page.wait("what the first undo undid",
              "window.softsight.messages.some(m => m.includes('undone: removed colours of blue'))")
    page.click_button("undo")
    page.wait("the undo", "window.softsight.status.hsv.join() === '%s'" % ",".join(map(str, before)))
    page.wait("what the undo undid",
              "window.softsight.messages.some(m => m.includes('undone: added colours of blue'))")
    page.click_button("maskview")
    page.wait("the mask view off", "!window.softsight.status.mask_view && window.softsight.shownMask === false")


def test_zoomed_pick(page, blue, frame):
    """Three wheel notches up near blue zoom in about the pointer (the image point under it stays),
    a right drag pans (the picture follows the pointer), the picture under blue's true position is
    blue, and a click there picks blue's colour: blue is then found within 1.5 px of the truth.
    "whole image" (z) zooms out again."""
    bx, by = float(blue["blue_x"]), float(blue["blue_y"])
    size = page.state("[window.softsight.hello && document.getElementById('view').clientWidth,"
                      " document.getElementById('view').clientHeight]")
    # The pointer 40 px right of and 30 px under blue, inside the picture.
    px, py = page.state("window.softsight.clientPoint(%f, %f)" % (min(bx + 40, 600), min(by + 30, 450)))
    px, py = round(px), round(py)
    under = page.state("window.softsight.imagePoint(%d, %d)" % (px, py))
    page.wheel_at(px, py, -300)
    page.wait("the zoom", "window.softsight.zoom().zoom > 2.5")
    zoom = page.state("window.softsight.zoom()")
    check(2.7 < zoom["zoom"] < 3.0, "three wheel notches zoomed to %.2fx, not 2.83x" % zoom["zoom"])
    after = page.state("window.softsight.imagePoint(%d, %d)" % (px, py))
    check(abs(after[0] - under[0]) < 0.5 and abs(after[1] - under[1]) < 0.5,
          "the image point under the wheel moved: (%.2f, %.2f) -> (%.2f, %.2f)" % (*under, *after))
    # A right drag of (-50, -35) screen px: the image point under the start ends under the end.
    rect = page.state("document.getElementById('view').getBoundingClientRect().toJSON()")
    sx, sy = round(rect["left"] + size[0] / 2), round(rect["top"] + size[1] / 2)
    grabbed = page.state("window.softsight.imagePoint(%d, %d)" % (sx, sy))
    page.right_drag(sx, sy, sx - 50, sy - 35)
    page.wait("the pan", "window.softsight.zoom().ox !== %r" % zoom["ox"])
    moved = page.state("window.softsight.imagePoint(%d, %d)" % (sx - 50, sy - 35))
    check(abs(moved[0] - grabbed[0]) < 0.5 and abs(moved[1] - grabbed[1]) < 0.5,
          "the pan did not follow the pointer: (%.2f, %.2f) is under the drag's end, not (%.2f, %.2f)"
          % (*moved, *grabbed))
    cx, cy = page.state("window.softsight.clientPoint(%f, %f)" % (bx, by))
    check(rect["left"] < cx < rect["left"] + size[0] and rect["top"] < cy < rect["top"] + size[1],
          "blue is off the zoomed picture")
    r, g, b = page.view_colour(cx, cy)
    check(b > r + 60 and b > g + 30, "the zoomed picture at blue's place is (%d, %d, %d), not blue" % (r, g, b))
    page.click_at(cx, cy)
    page.wait("blue found after the zoomed pick", "(window.softsight.row(%d) || {}).blue_found === 1" % frame)
    assert_near_truth(page.state("window.softsight.row(%d)" % frame), blue, ["red", "blue", "green"])
    page.driver.find_element("tag name", "body").send_keys("z")
    page.wait("the whole image", "window.softsight.zoom().zoom === 1")


def test_mm_scale(page, truth, frame, earlier):
    """Two points 400 px apart clicked with the mm scale tool and "100" typed: the scene's own
    scale (synth renders 0.25 mm per px). The frame on screen is measured again in mm, its chord
    the truth's within 0.5 %; a row from before the scale is plotted in mm too (its px times the
    scale); the readout says mm."""
    page.click_button("toolscale")
    page.click_image_point(100.0, 440.0)
    page.click_image_point(500.0, 440.0)
    field = page.driver.find_element("id", "scalemm")
    page.wait("the distance field", "!document.getElementById('scalebox').hidden")
    from selenium.webdriver.common.keys import Keys
    field.send_keys("100" + Keys.ENTER)
    page.wait("the scale", "window.softsight.status.mm_per_px")
    scale = page.state("window.softsight.status.mm_per_px")
    check(abs(scale - 0.25) < 0.25 * 0.005, "100 mm over 400 px gave %.5f mm/px" % scale)
    page.wait("the frame on screen in mm", "(window.softsight.row(%d) || {}).chord_mm != null" % frame)
    for f, row in ((frame, truth[frame]), (earlier, truth[earlier])):
        chord = page.state("window.softsight.lengthOf(%d, 'chord')" % f)
        true_mm = float(row["chord_px"]) * 0.25
        check(abs(chord - true_mm) < 0.005 * true_mm,
              "frame %d's chord %.2f mm, the truth %.2f mm" % (f, chord, true_mm))
    check(" mm" in page.driver.find_element("id", "readout").text, "the readout is not in mm")
    shown = re.search(r"scale ([0-9.]+) mm/px", page.driver.find_element("id", "status").text)
    check(shown and abs(float(shown.group(1)) - scale) < 1e-4, "the status line does not say the scale")


def test_hostile_messages(page):
    """Each bad message: one error on the page, nothing changed, the run goes on."""
    page.wait("the status of the frame on screen", "window.softsight.status.position === window.softsight.shownPosition")
    before = page.state("window.softsight.status")
    errors = page.state("window.softsight.errors.length")
    bad = ["not json", json.dumps({"type": "format_disk"}),
           json.dumps({"type": "seek", "position": 10 ** 9}),
           json.dumps({"type": "pick", "x": -5, "y": 10}),
           json.dumps({"type": "save", "name": "../../escaped.yaml"}),
           json.dumps({"type": "save", "name": "x" * 5000 + ".yaml"}),
           json.dumps({"type": "speed", "value": "fast"})]
    for text in bad:
        page.state("window.softsight.sendRaw(%s)" % json.dumps(text))
    page.wait("an error for each hostile message", "window.softsight.errors.length >= %d" % (errors + len(bad)))
    after = page.state("window.softsight.status")
    for key in ("position", "speed", "undo", "active", "method", "hsv", "paused"):
        check(before[key] == after[key], "a refused message changed %s: %s -> %s" %
              (key, before[key], after[key]))


def test_template_drag(page, truth, frame):
    """Switch to templates (SAD), then drag a box around green: its template is cut there and
    green is found where the truth is; undo takes the reselection back."""
    page.click_button("method")
    page.wait("the method switch", "window.softsight.status.method === 'sad'")
    undo = page.state("window.softsight.status.undo")
    x, y = float(truth["green_x"]), float(truth["green_y"])
    x0, y0 = page.state("window.softsight.clientPoint(%f, %f)" % (x - 14, y - 14))
    x1, y1 = page.state("window.softsight.clientPoint(%f, %f)" % (x + 14, y + 14))
    page.drag(x0, y0, x1, y1)
    page.wait("the reselection", "window.softsight.status.undo === %d" % (undo + 1))
    row = page.state("window.softsight.row(%d)" % frame)
    assert_near_truth(row, truth, ["red", "blue", "green"])
    check(page.state("window.softsight.status.active") == 2, "the drag did not select green")
    page.click_button("undo")
    page.wait("the undo", "window.softsight.status.undo === %d" % undo)


def comparable_rows(path):
    """The CSV's rows without the columns that time the run (proc_ms, latency_*)."""
    with open(path) as f:
        rows = list(csv.DictReader(f))
    return [{k: v for k, v in row.items() if k != "proc_ms" and not k.startswith("latency")}
            for row in rows]


def test_recording_reproduces(page, softsight, folder):
    """Record from the page while the video plays, stop: `softsight track` on the raw video
    with the recording's config gives the same rows."""
    start = page.state("window.softsight.status.position")
    page.click_button("record")
    page.wait("the recording", "window.softsight.status.recording")
    page.click_button("play")
    page.wait("30 frames recorded", "window.softsight.status.position >= %d" % (start + 30))
    print("the run's rate with %d pages open, recording: %.1f fps" % (
        page.state("window.softsight.status.pages"), page.state("window.softsight.status.fps")))
    page.click_button("record")
    page.wait("the recording's end", "!window.softsight.status.recording")
    prefix = os.path.join(folder, "serve-001")
    again = os.path.join(folder, "again.csv")
    subprocess.run([softsight, "track", "--config", prefix + ".yaml", "--input", prefix + ".raw.avi",
                    "-o", again], check=True, capture_output=True)
    recorded, tracked = comparable_rows(prefix + ".csv"), comparable_rows(again)
    check(len(recorded) >= 30, "only %d rows recorded" % len(recorded))
    check(recorded == tracked, "track does not reproduce the page's recording (%d and %d rows)"
          % (len(recorded), len(tracked)))


def test_compare(page, recording_csv):
    """A file that is no run's CSV is refused. The recording's CSV opened as the run to compare
    (read in the page): sought to a frame in
    the middle of it, the compared row is that very frame (matched by time alone), its markers
    are drawn on the picture within 1 px of the served run's (the same video and config), its
    curves are in the plots, and its numbers under the readout."""
    with open(recording_csv) as f:
        recorded = list(csv.DictReader(f))
    # Not a CSV of a run (the recording's config): refused with an error, nothing compared.
    errors = page.state("window.softsight.errors.length")
    page.driver.find_element("id", "comparefile").send_keys(recording_csv.replace(".csv", ".yaml"))
    page.wait("the refusal", "window.softsight.errors.length > %d && window.softsight.compare === null" % errors)
    page.driver.find_element("id", "comparefile").send_keys(recording_csv)
    page.wait("the compared run read", "window.softsight.compare && window.softsight.compare.rows === %d" % len(recorded))
    frame = int(recorded[len(recorded) // 2]["frame"])
    # The video may have played to its end meanwhile, and a seek from the end plays on: seek,
    # pause, seek again (the server takes them in order), so it stays on the frame.
    for message in ("{type: 'seek', position: %d}" % frame, "{type: 'pause'}",
                    "{type: 'seek', position: %d}" % frame):
        page.state("window.softsight.send(%s)" % message)
    # The readout is written by the same redraw that draws the compared markers: waited for with
    # them (a redraw of the frame before the seek settled may be the last one handled when the
    # markers count is first 3), and as shown text (innerText: what is rendered, as Selenium's
    # .text) at that same instant; a second read after the wait raced with later redraws.
    page.wait("the seek to a recorded frame, compared, its numbers shown",
              "window.softsight.shownPosition === %d && "
              "window.softsight.row(%d) !== null && window.softsight.compareDrawn === 3 && "
              "window.softsight.comparePlotted > 0 && "
              "document.getElementById('comparereadout').innerText.includes('frame %d ')"
              % (frame, frame, frame))
    other = page.state("window.softsight.compareRow(%d)" % frame)
    check(other is not None and other["frame"] == frame, "frame %d compared with %s" % (frame, other and other["frame"]))
    row = page.state("window.softsight.row(%d)" % frame)
    for name in ("red", "blue", "green"):
        d = ((other[name + "_x"] - row[name + "_x"]) ** 2 + (other[name + "_y"] - row[name + "_y"]) ** 2) ** 0.5
        check(d < 1, "%s: %.2f px from the served run's in the compared run" % (name, d))


def run(args, browser, driver):
    folder = tempfile.mkdtemp(prefix="softsight-serve-")
    config = os.path.join(folder, "cfg.yaml")
    video, truth_csv, browsers = render_with_pages(args.softsight, folder, 300, browser, driver, 2)
    with open(config, "w") as f:
        f.write(CONFIG)
    truth = truth_rows(truth_csv)
    server, url = start_server(args.softsight, folder, video, config)
    port = int(re.search(r":(\d+)/", url).group(1))
    token = re.search(r"token=([0-9a-f]+)", url).group(1)
    pages = []
    try:
        # A wrong or missing token: refused, the page and its WebSocket alike.
        check(http_status(url.replace(token, "0" * 32)) == 403, "a wrong token was not refused")
        check(http_status("http://127.0.0.1:%d/" % port) == 403, "a missing token was not refused")
        check(websocket_handshake_status(port, "/ws?token=" + "f" * 32) == 403,
              "a WebSocket with a wrong token was not refused")

        first = browsers[0]
        first.open(url)
        pages.append(first)
        first.wait("frames and results on the page", "window.softsight.framesShown >= 60 && window.softsight.results >= 60")
        check(first.state("window.softsight.controls"), "the first page does not control the run")
        print("the run's rate with 1 page open: %.1f fps" % first.state("window.softsight.status.fps"))
        median, p95, n = latency_figures(first)
        print("latency capture->page, 640x480 at 30 fps: median %.1f ms, p95 %.1f ms (%d frames);"
              " the page's clock offset estimate %.1f ms (true: 0), fastest ping %.1f ms"
              % (median, p95, n, first.state("window.softsight.clockOffsetMs"),
                 first.state("window.softsight.bestRttMs")))
        frame = first.state("window.softsight.shownFrame")
        row = first.state("window.softsight.row(%d)" % frame)
        assert_near_truth(row, truth[frame], ["red", "green"])
        check(row["blue_found"] == 0, "blue found with a yellow range")

        # Pause, then click blue on the picture: its colour is picked, and it is found where it is.
        first.click_button("play")
        first.wait("the pause", "window.softsight.status.paused")
        frame = first.wait("a steady frame",
                           "window.softsight.shownFrame === window.softsight.status.position && window.softsight.shownFrame")
        blue = truth[frame]
        # Blue is lost, so the click cannot name it: its row in the table makes it the active
        # marker, the one a click on no found marker picks for (as 2 does in the window).
        first.driver.find_element("css selector", "#markers tbody tr:nth-child(2)").click()
        first.wait("blue active", "window.softsight.status.active === 1")
        test_mask_click_grows(first, video, blue)
        test_zoomed_pick(first, blue, frame)
        # The status follows the result: polled, then checked.
        first.wait("blue's picked hue in the status", "window.softsight.status.hsv[0] !== 20", timeout=5)
        hsv = first.state("window.softsight.status.hsv")
        check(first.state("window.softsight.status.active") == 1 and 90 <= hsv[0] <= hsv[1] <= 140,
              "the pick did not set blue's hue: %s" % hsv)

        # A seek by a click on the timeline lands on that frame, tracked where the truth is.
        target = 200
        rect = first.state("document.getElementById('timeline').getBoundingClientRect().toJSON()")
        first.click_at(rect["left"] + first.state("window.softsight.positionX(%d)" % target),
                       rect["top"] + rect["height"] / 2)
        first.wait("the seek to %d" % target,
                   "window.softsight.shownPosition === %d && window.softsight.row(%d) !== null" % (target, target))
        check(first.state("window.softsight.shownFrame") == target, "the picture is another frame")
        assert_near_truth(first.state("window.softsight.row(%d)" % target), truth[target],
                          ["red", "blue", "green"])

        test_mm_scale(first, truth, target, frame)
        test_hostile_messages(first)

        # The speed selector sets the paced file's speed (0.1x .. 4x), and back.
        from selenium.webdriver.support.ui import Select
        for speed in ("0.5", "1"):
            Select(first.driver.find_element("id", "speed")).select_by_value(speed)
            first.wait("speed " + speed, "window.softsight.status.speed === %s" % speed)

        # A second browser sees the same run, read-only.
        second = browsers[1]
        second.open(url)
        pages.append(second)
        second.wait("the second page's picture", "window.softsight.shownPosition === %d" % target)
        check(not second.state("window.softsight.controls"), "the second page controls too")
        errors = second.state("window.softsight.errors.length")
        second.click_button("fwd")
        second.wait("the read-only refusal", "window.softsight.errors.length > %d" % errors)
        check(first.state("window.softsight.status.position") == target, "a read-only page moved the run")
        first.click_button("fwd")
        for page in pages:
            page.wait("the step seen by both pages", "window.softsight.shownPosition === %d" % (target + 1))

        # The page's CSV export: the CSV's columns, one row per frame received, in order.
        lines = first.state("window.softsight.csvText()").splitlines()
        header = lines[0].split(",")
        check(header[:2] == ["frame", "time_s"] and "blue_x" in header and "angle_deg" in header,
              "the page's CSV has other columns: %s" % header[:8])
        frames = [int(line.split(",")[0]) for line in lines[1:]]
        check(frames == sorted(set(frames)) and target in frames and len(frames) >= 60,
              "the page's CSV rows: %d, not in frame order or without frame %d" % (len(frames), target))

        # Saved only in the server's folder, under a plain name.
        first.click_button("save")
        saved = os.path.join(folder, "markers.web.yaml")
        # (Read until whole: the file is written while this polls.)
        wait_for("the saved config with the page's scale", lambda: os.path.exists(saved) and
                 re.search(r"scale_from_points:[\s\S]*distance_mm: 100\b", open(saved).read()))

        # 100 connections opened and dropped: the server goes on serving both pages.
        open_and_drop(port, 100, token)
        check(http_status(url) == 200, "the page is not served after 100 dropped connections")
        first.click_button("back")
        for page in pages:
            page.wait("a step after the flood", "window.softsight.shownPosition === %d" % target)
        test_template_drag(first, truth[target], target)
        test_recording_reproduces(first, args.softsight, folder)
        test_compare(first, os.path.join(folder, "serve-001.csv"))
        if args.screenshot:
            first.state("window.softsight.send({type: 'pause'})")
            first.wait("the pause", "window.softsight.status.paused || window.softsight.status.ended")
            time.sleep(0.3)  # Only for the picture: the plots redraw at most every 120 ms.
            first.driver.save_screenshot(args.screenshot)
    except Exception:
        # What the pages said, for the failure's report.
        for i, page in enumerate(pages):
            print("page %d messages: %s\n        errors: %s\n        status: %s" % (
                i, page.state("window.softsight.messages.slice(-8)"),
                page.state("window.softsight.errors.slice(-8)"), page.state("window.softsight.status")))
        raise
    finally:
        quit_pages(browsers)
        stop_server(server)
    shutil.rmtree(folder)


if __name__ == "__main__":
    sys.exit(browser_test_main(__doc__, run, "serve browser test"))
