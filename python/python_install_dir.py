"""Where `cmake --install --prefix P` puts the softsight package: the directory under P that this
interpreter searches, so that `python3 -c "import softsight"` works with no setting.

  P is the user base (~/.local, or $PYTHONUSERBASE)  -> the user site (lib/python3.X/site-packages)
  P is a virtual environment                         -> its site-packages
  P is /usr (Debian)                                 -> lib/python3/dist-packages
  P is /usr/local (Debian)                           -> lib/python3.X/dist-packages
  any other P                                        -> this interpreter's scheme's place under P
                                                        (Debian: lib/python3.X/dist-packages),
                                                        which needs PYTHONPATH

Prints two lines: the directory relative to P, then "found" or "PYTHONPATH" (whether this
interpreter finds it there by itself). Run at install time (python/install_package.cmake), since
--prefix is known only then:  python3 python_install_dir.py P
"""

from __future__ import annotations

import os
import site
import sys
import sysconfig


def searched_directories() -> list[str]:
    """The package directories this interpreter searches by itself, the user site first (it is
    searched whether or not it exists yet; site.getsitepackages() lists the others)."""
    directories = []
    if site.ENABLE_USER_SITE:
        directories.append(site.getusersitepackages())
    directories += site.getsitepackages()
    return directories


def install_dir(prefix: str) -> tuple[str, bool]:
    prefix = os.path.realpath(prefix)
    candidates = []
    for directory in searched_directories():
        path = os.path.realpath(directory)
        if path.startswith(prefix + os.sep):
            candidates.append(os.path.relpath(path, prefix))
    if candidates:
        # /usr holds several (/usr/local/lib/python3.X/dist-packages too): the shortest is the
        # prefix's own (Debian's /usr/lib/python3/dist-packages); ties keep Python's order.
        return min(candidates, key=lambda relative: relative.count(os.sep)), True
    # Nowhere this interpreter looks: its own scheme's layout, as a prefix of its own would have.
    platlib = sysconfig.get_path("platlib", vars={"platbase": "/@", "base": "/@"})
    relative = os.path.relpath(platlib, "/@")
    if relative.startswith("local" + os.sep):  # Debian's posix_local scheme: /usr/local/lib/...
        relative = relative[len("local" + os.sep):]
    return relative, False


if __name__ == "__main__":
    directory, found = install_dir(sys.argv[1])
    print(directory)
    print("found" if found else "PYTHONPATH")
