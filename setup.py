"""Builds the softsight Python package with CMake, for `pip install .` (see pyproject.toml).

The extension (softsight._core) and the package's files are what CMake assembles in
<build>/python/softsight; this script only asks CMake for them and hands them to setuptools,
so a pip-installed package is the same as the one the tests import from the build tree.
"""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
from pathlib import Path
from typing import Optional, TextIO

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext
from setuptools.command.build_py import build_py

ROOT = Path(__file__).resolve().parent
# The pure-Python files (python/CMakeLists.txt's SOFTSIGHT_PYTHON_FILES, also copied by CMake).
PACKAGE_FILES = re.search(r"set\(SOFTSIGHT_PYTHON_FILES\s+([^)]*)\)",
                          (ROOT / "python" / "CMakeLists.txt").read_text()).group(1).split()


def project_version() -> str:
    match = re.search(r"project\(softsight VERSION ([0-9.]+)", (ROOT / "CMakeLists.txt").read_text())
    if not match:
        raise RuntimeError("setup.py: no `project(softsight VERSION x.y.z` in CMakeLists.txt")
    return match.group(1)


def cmake_build_dir() -> Path:
    given = os.environ.get("SOFTSIGHT_BUILD_DIR")
    return Path(given).resolve() if given else ROOT / "build" / "pip"


def build_output() -> Optional[TextIO]:
    """Where CMake's own output goes while pip builds: the terminal, when there is one.

    pip captures a build backend's output and shows none of it without -v: a first build printed
    only "still running..." for 2-3 minutes. So the configure and build steps write to the
    controlling terminal (/dev/tty), and their progress shows as in a plain CMake build. Without
    a terminal (CI, a service, cron) they write to the backend's output as before, which pip shows
    with -v or when the build fails. SOFTSIGHT_BUILD_QUIET=1 keeps the terminal quiet.
    """
    if os.environ.get("SOFTSIGHT_BUILD_QUIET", "") not in ("", "0"):
        return None
    try:
        return open("/dev/tty", "w")  # Closed by build_extension when the build is done.
    except OSError:  # No controlling terminal.
        return None


def shared_libraries(build: Path) -> list[Path]:
    """The tree's shared softsight libraries by soname (libsoftsight_core.so.0.1), if it has them."""
    cache = (build / "CMakeCache.txt").read_text()
    if not re.search(r"^BUILD_SHARED_LIBS:BOOL=(ON|1|TRUE|YES)$", cache, re.MULTILINE | re.IGNORECASE):
        return []
    return sorted(p for p in (build / "src").glob("*/libsoftsight_*.so.*")
                  if re.fullmatch(r"libsoftsight_[a-z]+\.so\.[0-9]+\.[0-9]+", p.name))


def run(command: list[str], output: Optional[TextIO]) -> None:
    print("setup.py:", " ".join(command), file=output or sys.stdout, flush=True)
    subprocess.run(command, check=True, stdout=output, stderr=output)


class CMakeBuildExt(build_ext):
    """Configures (unless reusing SOFTSIGHT_BUILD_DIR) and builds the CMake target softsight_python."""

    def build_extension(self, ext: Extension) -> None:
        build = cmake_build_dir()
        output = build_output()
        if output:
            # A line of its own: pip's "Building wheel ... -" spinner has the cursor.
            print("\nsetup.py: building the C++ extension with CMake (a first build takes a few "
                  "minutes); its progress follows", file=output, flush=True)
        if not (build / "CMakeCache.txt").exists():
            generator = ["-G", "Ninja"] if shutil.which("ninja") else []
            # Static libraries: the extension carries the library's code, nothing to install beside it.
            run(["cmake", "-S", str(ROOT), "-B", str(build), *generator, "-DCMAKE_BUILD_TYPE=Release",
                 "-DSOFTSIGHT_BUILD_TESTS=OFF", "-DSOFTSIGHT_BUILD_BENCHMARKS=OFF",
                 "-DBUILD_SHARED_LIBS=OFF", "-DSOFTSIGHT_BUILD_PYTHON=ON",
                 f"-DPython3_EXECUTABLE={sys.executable}"], output)
        run(["cmake", "--build", str(build), "--target", "softsight_python",
             "--parallel", str(os.cpu_count() or 1)], output)
        if output:
            output.close()
        package = build / "python" / "softsight"
        built = sorted(package.glob("_core*.so"))
        if len(built) != 1:
            raise RuntimeError(f"setup.py: expected one _core*.so in {package}, found {len(built)}")
        target = Path(self.get_ext_fullpath(ext.name))
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(built[0], target)
        # A reused tree built with shared libraries (the default, SOFTSIGHT_BUILD_DIR): the package
        # carries copies of them, by soname, where the extension looks first ($ORIGIN).
        for library in shared_libraries(build):
            shutil.copyfile(library, target.parent / library.name)


class PackageFiles(build_py):
    """The package's Python files, stubs and py.typed, as listed for CMake."""

    def run(self) -> None:
        super().run()
        destination = Path(self.build_lib) / "softsight"
        destination.mkdir(parents=True, exist_ok=True)
        for name in PACKAGE_FILES:
            shutil.copyfile(ROOT / "python" / "softsight" / name, destination / name)


# setuptools' own scratch (its build/ and egg-info) goes inside the CMake build tree, not beside
# the sources, where ./build is CMake's.
SCRATCH = cmake_build_dir() / "setuptools"

# pip (setuptools.build_meta) runs this file as __main__; a test reads build_output from it.
if __name__ == "__main__":
    SCRATCH.mkdir(parents=True, exist_ok=True)
    setup(
        name="softsight",
        version=project_version(),
        description="Measure soft robots with a camera",
        license="Apache-2.0",
        python_requires=">=3.8",
        install_requires=["numpy"],
        extras_require={"batch": ["dask[distributed]"], "pandas": ["pandas"]},
        packages=["softsight"],
        package_dir={"softsight": "python/softsight"},
        ext_modules=[Extension("softsight._core", sources=[])],
        cmdclass={"build_ext": CMakeBuildExt, "build_py": PackageFiles},
        zip_safe=False,
        options={"build": {"build_base": str(SCRATCH)}, "egg_info": {"egg_base": str(SCRATCH)}},
    )
