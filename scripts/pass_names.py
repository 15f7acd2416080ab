"""The pass names the scripts use, read from the program itself
(`accretion passes --json`, the pass table of include/accretion/core/pass.h):
`PASS.traceShadowRays` is the string "traceShadowRays", and a name that is not
a pass fails here, by name, instead of silently emptying a join of timings
with counters. The program is $ACCRETION, else build/accretion.

    sys.path.insert(0, str(REPO / "scripts")); from pass_names import PASS
"""
import json
import os
import pathlib
import subprocess

_REPO = pathlib.Path(__file__).resolve().parent.parent
_PROGRAM = os.environ.get("ACCRETION", str(_REPO / "build" / "accretion"))


def _read_table():
    try:
        out = subprocess.run([_PROGRAM, "passes", "--json"], check=True, capture_output=True, text=True).stdout
    except (OSError, subprocess.CalledProcessError) as e:
        raise SystemExit(f"pass_names: '{_PROGRAM} passes --json' failed ({e}); build accretion or set ACCRETION")
    return json.loads(out)["passes"]


TABLE = _read_table()
NAMES = tuple(p["name"] for p in TABLE)


class _Passes:
    def __getattr__(self, name):
        if name in NAMES:
            return name
        raise AttributeError(f"'{name}' is not a pass of `accretion passes` ({', '.join(NAMES)})")


PASS = _Passes()
