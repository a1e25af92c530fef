#!/usr/bin/env python3
"""softsight serve --simulate in a real headless browser (chromium + chromium-driver through
python3-selenium): the control panel shows the board's and the host's limits; out-of-range and
read-only commands are refused with an error and change nothing; a target runs the simulated
rig's closed loop; a second browser sees the same run and its STOP vents the rig although the
first page controls it (STOP to vented, measured in the page); and a page that leaves mid-run
leaves the rig held for controller.hold_s, then vented.

Every wait is a condition on the page's state (window.softsight) checked in the page on every
message and redraw (Page.wait): no polling, and no sleep decides a result. The server and both
browsers start at once. Exit code 77 (ctest: skipped) when chromium, its driver or selenium
is missing.

  serve_rig_browser_test.py --softsight build/src/app/softsight [--screenshot docs/images/serve-rig.png]
"""
import json
import os
import shutil
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from serve_browser_test import (browser_test_main, check, quit_pages, serve_with_pages,  # noqa: E402
                                stop_server, webdriver_wait)


def wait(page, what, expression, timeout=10.0):
    # On failure: the rig's state and the frame on screen (its markers' statuses).
    return webdriver_wait(page, what, expression, timeout,
                          "[window.softsight.rig, window.softsight.row(window.softsight.shownFrame)]")


def run_target(page, degrees):
    field = page.driver.find_element("id", "rigtarget")
    field.clear()
    field.send_keys(str(degrees))
    page.click_button("rigrun")


def test_refusals(page):
    """Out of range, malformed, pause: an error on the page each, the rig still idle and vented."""
    errors = page.state("window.softsight.errors.length")
    bad = ['{"type":"rig_run","target_deg":500}', '{"type":"rig_run","target_deg":"x"}',
           '{"type":"rig_run"}', '{"type":"rig_profile","text":"step 999\\n"}',
           '{"type":"rig_profile","text":"' + "#" * 5000 + '"}', '{"type":"pause"}',
           '{"type":"step","delta":1}', '{"type":"seek","position":0}']
    for text in bad:
        page.state("window.softsight.sendRaw(%s)" % json.dumps(text))
    wait(page, "an error for each refused message",
         "window.softsight.errors.length >= %d" % (errors + len(bad)))
    check(page.state("window.softsight.rig.state") == "idle",
          "a refused message started the rig: %s; %s" % (page.state("window.softsight.rig"),
                                                         page.state("window.softsight.messages")))
    check(page.state("window.softsight.rig.vented"), "the idle rig is not vented")
    check(not page.state("window.softsight.status.paused"), "a refused pause paused the run")


CONTROL_COLUMNS = ["target_deg", "setpoint_kpa", "board_pressure_kpa", "board_setpoint_kpa", "duty",
                   "board_flags", "control_action", "rig_state"]


def test_control_columns_and_whole_run(page):
    """Each frame's row carries the loop's columns (control's CSV names), with the values the
    rig's own message said for that frame; the page's CSV has them. The traces switched to the
    whole run span it from the first sample this page got."""
    rig = page.state("window.softsight.rig")
    row = page.state("window.softsight.rowsIn().find(r => Math.abs(r.time_s - %f) < 5e-4) || null" % rig["t"])
    check(row is not None, "no row for the rig's frame at t %.3f s" % rig["t"])
    check(row["target_deg"] == 120 and row["rig_state"] == 1 and
          abs(row["setpoint_kpa"] - rig["setpoint_kpa"]) < 0.006 and
          abs(row["board_pressure_kpa"] - rig["pressure_kpa"]) < 0.006 and abs(row["duty"] - rig["duty"]) < 6e-4,
          "the row at t %.3f s: %s; the rig said %s" % (rig["t"], {k: row.get(k) for k in CONTROL_COLUMNS}, rig))
    header = page.state("window.softsight.csvText()").splitlines()[0].split(",")
    check(all(c in header for c in CONTROL_COLUMNS), "the page's CSV has no control columns: %s" % header)
    from selenium.webdriver.support.ui import Select
    Select(page.driver.find_element("id", "rigspan")).select_by_value("whole")
    wait(page, "the whole run drawn", "window.softsight.rigTrace.whole && "
         "window.softsight.rigTrace.t0 === Math.min(window.softsight.rigStates[0].t, window.softsight.rigTrace.t1 - 1)")
    Select(page.driver.find_element("id", "rigspan")).select_by_value("last")
    wait(page, "the last 20 s drawn", "!window.softsight.rigTrace.whole && "
         "Math.abs(window.softsight.rigTrace.t1 - window.softsight.rigTrace.t0 - 20) < 1e-9")


def run(args, browser, driver):
    folder = tempfile.mkdtemp(prefix="softsight-serve-rig-")
    # The server and both browsers start at once.
    server, url, browsers = serve_with_pages(args.softsight, ["--simulate", "--port", "0", "--folder", folder],
                                             browser, driver, 2)
    pages = []
    figures = {}
    try:
        first = browsers[0]
        first.open(url)
        pages.append(first)
        wait(first, "the panel, idle and vented",
             "window.softsight.rig !== null && window.softsight.rigLimits !== null && "
             "window.softsight.controls && window.softsight.rig.state === 'idle' && window.softsight.rig.vented")
        check(first.driver.find_element("id", "rig").is_displayed(), "the rig's panel is hidden")
        limits_text = first.driver.find_element("id", "riglimits").text
        check("limit 50 kPa" in limits_text and "0..45 kPa" in limits_text and "watchdog 250 ms" in limits_text,
              "the limits shown: %r" % limits_text)
        test_refusals(first)

        run_target(first, 120)
        wait(first, "the loop running and the pressure building",
             "window.softsight.rig.state === 'running' && window.softsight.rig.pressure_kpa > 5")
        wait(first, "the angle near 120 deg", "Math.abs(window.softsight.rig.measured_deg - 120) < 5")
        test_control_columns_and_whole_run(first)

        # A second browser: the same run, read-only; its own STOP vents it all the same.
        second = browsers[1]
        second.open(url)
        pages.append(second)
        wait(second, "the second page sees the run",
             "window.softsight.rig !== null && window.softsight.rig.state === 'running'")
        check(not second.state("window.softsight.controls"), "the second page controls too")
        check(not second.driver.find_element("id", "rigrun").is_enabled(),
              "a read-only page may press run")
        errors = second.state("window.softsight.errors.length")
        second.state("window.softsight.sendRaw('{\"type\":\"rig_run\",\"target_deg\":150}')")
        wait(second, "the read-only refusal", "window.softsight.errors.length > %d" % errors)
        check(first.state("window.softsight.rig.target_deg") == 120, "a read-only page changed the target")
        if args.screenshot:
            wait(first, "a few seconds of traces", "window.softsight.rig.t > 4")
            first.driver.save_screenshot(args.screenshot)

        before_kpa = second.state("window.softsight.rig.pressure_kpa")
        second.click_button("rigstop")
        wait(second, "the STOP seen vented", "window.softsight.rigStopLatencyMs.length === 1")
        figures["stop_ms"] = second.state("window.softsight.rigStopLatencyMs[0]")
        wait(first, "the first page sees the vent too",
             "window.softsight.rig.state === 'idle' && window.softsight.rig.vented")
        wait(second, "the pressure falling after STOP",
             "window.softsight.rig.pressure_kpa < %f" % (0.3 * before_kpa))

        # The page that runs the loop leaves mid-run: held for hold_s, then vented.
        run_target(first, 120)
        wait(first, "the second run",
             "window.softsight.rig.state === 'running' && window.softsight.rig.pressure_kpa > 5")
        start = second.state("window.softsight.rigStates.length")
        first.quit()
        pages.remove(first)
        wait(second, "the hold, then the vent",
             "window.softsight.rigStates.slice(%d).some(s => s.state === 'idle' && s.vented)" % start)
        states = second.state("window.softsight.rigStates.slice(%d)" % start)
        holding = [s for s in states if s["state"] == "holding"]
        idle = [s for s in states if s["state"] == "idle" and s["vented"]]
        check(holding and idle and holding[0]["t"] < idle[0]["t"],
              "no hold before the vent: %s" % states)
        hold_s = second.state("window.softsight.rigLimits.hold_s")
        # The hold began hold_s - hold_left_s before the first frame that said holding. The vent
        # comes with the first frame at or after hold_s on the frames' clock: the frame before it
        # still held. (A loaded machine may space the frames out; the hold is on their clock.)
        began = holding[0]["t"] - (hold_s - holding[0]["hold_left_s"])
        figures["hold_s"] = idle[0]["t"] - began
        figures["last_held_s"] = idle[0]["prev_t"] - began
        # (The page's times are rounded to 1 ms.)
        check(figures["hold_s"] >= hold_s - 2e-3 and figures["last_held_s"] < hold_s - 1e-3,
              "vented %.3f s after the page left, the last frame held at %.3f s (hold_s %.2f s)"
              % (figures["hold_s"], figures["last_held_s"], hold_s))
        check(any("left mid-run" in m for m in second.state("window.softsight.messages")),
              "the page did not say why the rig vented")
    except Exception:
        for i, page in enumerate(pages):
            print("page %d messages: %s\n        errors: %s\n        rig: %s" % (
                i, page.state("window.softsight.messages.slice(-8)"),
                page.state("window.softsight.errors.slice(-8)"), page.state("window.softsight.rig")))
        raise
    finally:
        quit_pages(browsers)
        out, err = stop_server(server)
    check("left mid-run" in out and "STOP" in out, "the server's log: %s" % out[-2000:])
    print("STOP pressed on a read-only page -> the page shows the rig vented: %.1f ms" % figures["stop_ms"])
    print("the page running the loop left: held on the frames' clock until %.3f s (hold_s 0.5 s), "
          "vented with the next frame, at %.3f s" % (figures["last_held_s"], figures["hold_s"]))
    shutil.rmtree(folder)


if __name__ == "__main__":
    sys.exit(browser_test_main(__doc__, run, "serve rig browser test"))
