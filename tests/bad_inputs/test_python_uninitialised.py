"""Issue 80, case 6: an instance of one of the module's types made by `T.__new__(T)` without `__init__` (a Joint,
a Map, a SphereFit) is unusable: every method and property raises TypeError naming the class, none crashes the
interpreter (pybind11 would hand the method an unconstructed C++ object). Every type of the extension and every
method and property of each is tried, in a child interpreter, so that a crash fails the test instead of the run."""
import json
import os
import subprocess
import sys

import pytest

pytest.importorskip("impinge")

# Run in a child: for every pybind11 type of impinge._impinge (and the package's Python subclass of Joint), every
# property read and every method called with as many None arguments as it requires, on an instance made by __new__;
# prints {"Class.name": "ExceptionType: message"} and the names of the types seen.
PROBE = r'''
import inspect, json
import impinge, impinge._impinge as ext

def required_arguments(doc):
    """Positional parameters without a default after self, from pybind11's signature line 'f(self: T, a: int, b=1)'."""
    line = (doc or "").splitlines()[0] if doc else ""
    if "(" not in line:
        return 0
    inside, depth, parts, cur = line[line.index("(") + 1:], 0, [], ""
    for ch in inside:
        if ch in "[(":
            depth += 1
        elif ch in "])":
            if depth == 0:
                break
            depth -= 1
        if ch == "," and depth == 0:
            parts.append(cur); cur = ""
        else:
            cur += ch
    parts.append(cur)
    params = [p.strip() for p in parts[1:] if p.strip()]
    return sum(1 for p in params if "=" not in p and not p.startswith("*"))

types = [t for t in vars(ext).values() if isinstance(t, type) and type(t).__name__ == "pybind11_type"]
types.append(impinge.Joint)  # the package's subclass (VTK files)
out, seen = {}, []
for cls in types:
    seen.append(cls.__module__ + "." + cls.__name__)
    obj = cls.__new__(cls)
    for name in sorted(set(dir(cls)) - set(dir(object))):
        attr = inspect.getattr_static(cls, name)
        key = cls.__module__ + "." + cls.__name__ + "." + name
        try:
            if isinstance(attr, property):
                getattr(obj, name)
            elif type(attr).__name__ == "instancemethod":
                getattr(obj, name)(*[None] * required_arguments(attr.__doc__))
            else:
                continue  # static methods, __module__, __doc__, the Python subclass's own __init__
            out[key] = "no error"
        except Exception as e:
            out[key] = type(e).__name__ + ": " + str(e)
print(json.dumps({"results": out, "types": seen}))
'''


def test_every_method_and_property_of_an_uninitialised_instance_raises_type_error():
    r = subprocess.run([sys.executable, "-c", PROBE], capture_output=True, text=True, timeout=60,
                       env=dict(os.environ))
    assert r.returncode == 0, f"the probe crashed (exit {r.returncode}): {r.stderr[-2000:]}"
    report = json.loads(r.stdout.splitlines()[-1])
    types = set(report["types"])
    # The types the module binds today: a new one joins the probe by itself; these must be among them.
    assert {"impinge._impinge.Joint", "impinge._impinge.Map", "impinge._impinge.SphereFit"} <= types, types
    results = report["results"]
    for must in ("Joint.motion", "Joint.cor", "Joint.rom_limits", "Joint.save_maps", "Map.values",
                 "Map.node_directions", "SphereFit.radius"):
        assert any(k.endswith("_impinge." + must) for k in results), (must, sorted(results))
    assert len(results) >= 35, sorted(results)
    for key, outcome in results.items():
        assert outcome.startswith("TypeError: ") and "is not initialised" in outcome, (key, outcome)
        cls = key.split(".")[-2]
        assert f"impinge.{cls} object" in outcome and f"{cls}.__new__" in outcome, (key, outcome)


def test_initialised_instances_still_work():
    impinge = pytest.importorskip("impinge")
    h = impinge.generated_hip(triangles=2000)
    fit = impinge.locate_femoral_head(*h["femur"])
    assert abs(fit.radius - h["head_radius_mm"]) < 0.5
    j = impinge.Joint(h["femur"], h["pelvis"], neutral="scan", resolution=2.0, query_strategy="maps")
    assert j.femur_map.values.shape == (j.femur_map.num_nodes,)
    assert len(j.motion([[0, 0, 0], [10, 0, 0]])["femur_min_gap_mm"]) == 2
