"""`pip install .` shows the CMake build's progress: pip captures a build backend's output and
showed only "still running..." for 2-3 minutes, so setup.py's build writes to the terminal when
there is one (build_output), and where it always did when there is none."""

from __future__ import annotations

import os
import pty
import sys
from pathlib import Path

SOURCE_DIR = os.environ.get("SOFTSIGHT_SOURCE_DIR", str(Path(__file__).resolve().parents[2]))
SETUP = Path(SOURCE_DIR) / "setup.py"

# Loads setup.py without building (it builds only as __main__; loading it costs the setuptools
# import, so one process asks all three questions) and reports what build_output() gives.
CHILD = """
import os, runpy, sys
build_output = runpy.run_path(sys.argv[1], run_name="softsight_setup")["build_output"]
terminal = sys.__stdout__
sys.stdout = open(os.devnull, "w")
output = build_output()
if output is not None:  # Written through the file build_output opened, not through stdout.
    output.write("terminal\\n")
    output.close()
os.environ["SOFTSIGHT_BUILD_QUIET"] = "1"
terminal.write("quiet:" + ("none" if build_output() is None else "terminal") + "\\n")
del os.environ["SOFTSIGHT_BUILD_QUIET"]
terminal.flush()
pid = os.fork()
if pid == 0:
    os.setsid()  # A new session has no controlling terminal (as under CI or a service).
    os._exit(0 if build_output() is None else 1)
_, status = os.waitpid(pid, 0)
alone = "none" if os.waitstatus_to_exitcode(status) == 0 else "terminal"
terminal.write("no-terminal:" + alone + "\\n")
"""


def test_the_build_writes_to_the_terminal_when_there_is_one():
    pid, master = pty.fork()
    if pid == 0:  # The child: the pty is its stdin, stdout, stderr and /dev/tty.
        os.execv(sys.executable, [sys.executable, "-c", CHILD, str(SETUP)])
    output = b""
    while True:
        try:
            chunk = os.read(master, 1024)
        except OSError:  # EIO: the child closed the terminal's last descriptor.
            break
        if not chunk:
            break
        output += chunk
    _, status = os.waitpid(pid, 0)
    os.close(master)
    assert os.waitstatus_to_exitcode(status) == 0, output
    assert output.decode().split() == ["terminal", "quiet:none", "no-terminal:none"]
