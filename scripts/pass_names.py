"""The pass names the scripts use, read from the one list the C++ has
(kPassNames in include/accretion/core/pass_timer.h): `PASS.traceShadowRays`
is the string "traceShadowRays", and a name that is not a pass fails here,
by name, instead of silently emptying a join of timings with counters.

    sys.path.insert(0, str(REPO / "scripts")); from pass_names import PASS
"""
import pathlib
import re

_HEADER = pathlib.Path(__file__).resolve().parent.parent / "include" / "accretion" / "core" / "pass_timer.h"


def _read_names():
    text = _HEADER.read_text()
    m = re.search(r"kPassNames\s*=\s*\{(.*?)\};", text, re.S)
    if not m:
        raise SystemExit(f"{_HEADER}: no kPassNames list")
    return tuple(re.findall(r'"(\w+)"', m.group(1)))


NAMES = _read_names()


class _Passes:
    def __getattr__(self, name):
        if name in NAMES:
            return name
        raise AttributeError(f"'{name}' is not a pass of {_HEADER.name} ({', '.join(NAMES)})")


PASS = _Passes()
