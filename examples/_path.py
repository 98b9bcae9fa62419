# SPDX-License-Identifier: MIT
"""Makes `import mlcontact` work for the examples run from a source checkout: uses Debian's
/usr/bin/python3 (it has numpy and matplotlib; a python3 earlier on PATH may not) and the module
the default build puts in build/python (PYTHONPATH, if set, is searched first)."""
import os
import sys

_ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def setup():
    try:
        import numpy  # noqa: F401
    except ImportError:
        if os.path.exists("/usr/bin/python3") and os.path.realpath(sys.executable) != os.path.realpath("/usr/bin/python3"):
            os.execv("/usr/bin/python3", ["/usr/bin/python3"] + sys.argv)
        raise
    try:
        import mlcontact  # noqa: F401
    except ImportError:
        sys.path.append(os.path.join(_ROOT, "build", "python"))
        import mlcontact  # noqa: F401
