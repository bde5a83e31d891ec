"""Every front end against the one option table (the session layer's, impinge.options()).

Invariants: the CLI's commands, Python's Joint, rom_limits, rom_map and generated_hip, the stub file and the
study spec expose exactly the table's options, with its defaults, units and types; the stub's signatures are
the module's; every study key is documented. Each test fails on one option added, dropped or changed in one
place only."""
import ast
import os
import re
import subprocess

import pytest

import impinge
from impinge.study import spec
from test_impinge import CLI

HERE = os.path.dirname(__file__)
STUB = os.path.join(HERE, "..", "impinge", "__init__.pyi")
STUDIES_DOC = os.path.join(HERE, "..", "..", "docs", "studies.md")
OPTIONS = impinge.options()


def rows(use):
    return [o for o in OPTIONS if use in o["uses"]]


def same_value(o, shown, expected):
    """A value as the CLI shows it (text) against the table's default (Python)."""
    if o["type"] in ("number", "integer"):
        return float(shown) == float(expected)
    if o["type"] == "numbers":
        return [float(x) for x in shown.split(",")] == [float(x) for x in expected]
    if o["type"] == "on_off":
        return shown == ("on" if expected else "off")
    if o["type"] == "point" and expected is None:
        return shown == "auto"
    return shown == str(expected)


def type_name(o):
    """The value's name in --help (apps/impinge_main.cpp): its choices, or its kind with the unit."""
    unit = f" {o['unit']}" if o["unit"] else ""
    return {"choice": "|".join(o["choices"]), "on_off": "on|off", "point": "auto|X,Y,Z mm", "region": "X,Y,Z,R mm",
            "numbers": "A,B,..." + unit, "path": "PATH", "mesh": "PATH", "integer": "INT" + unit,
            "number": "NUMBER" + unit, "text": "TEXT", "flag": ""}[o["type"]]


def cli_help(command):
    """{option: the rest of its line} of `impinge COMMAND --help`."""
    text = subprocess.run([CLI, command, "--help"], check=True, capture_output=True, text=True).stdout
    return {m.group(1): m.group(2) for m in re.finditer(r"^[ \t]+--([a-z][a-z-]*)[ \t]?(.*)$", text, re.M)
            if m.group(1) != "help"}


@pytest.mark.parametrize("command", ["distance", "motion", "rom", "generate", "morphology", "plan", "view"])
def test_cli_options_are_the_tables(command):
    shown = cli_help(command)
    table = {o["name"]: o for o in rows(command)}
    assert set(shown) == set(table), (sorted(set(shown) - set(table)), sorted(set(table) - set(shown)))
    for name, rest in shown.items():
        o = table[name]
        assert rest.startswith(type_name(o)), (name, rest, type_name(o))  # the unit or the choices
        after = rest[len(type_name(o)):]
        default = after[1:].split()[0] if after.startswith("=") else None
        if o["type"] == "flag" or (o["default"] is None and o["type"] != "point"):
            assert default is None, (name, default)
        else:
            assert default is not None and same_value(o, default, o["default"]), (name, default, o["default"])


def stub_functions():
    """{name: ast.FunctionDef} of the stub: module functions and Joint's methods as 'Joint.name'."""
    tree = ast.parse(open(STUB).read())
    out = {n.name: n for n in tree.body if isinstance(n, ast.FunctionDef)}
    for c in (n for n in tree.body if isinstance(n, ast.ClassDef)):
        out.update({f"{c.name}.{f.name}": f for f in c.body if isinstance(f, ast.FunctionDef)})
    return out


def stub_parameters(fn):
    """[(name, default or ...)] of a stub function, self and **kwargs left out."""
    a = fn.args
    positional = a.posonlyargs + a.args
    defaults = [...] * (len(positional) - len(a.defaults)) + [ast.literal_eval(d) for d in a.defaults]
    out = [(x.arg, d) for x, d in zip(positional, defaults) if x.arg != "self"]
    out += [(x.arg, ... if d is None else ast.literal_eval(d)) for x, d in zip(a.kwonlyargs, a.kw_defaults)]
    return out


def module_parameters(obj):
    """[(name, default or ...)] from a pybind11 function's signature line (its docstring's first line)."""
    line = obj.__doc__.strip().splitlines()[0]
    inside = line[line.index("(") + 1:line.rindex(") ->")]
    params, depth, cur = [], 0, ""
    for ch in inside + ",":
        depth += ch in "([{"
        depth -= ch in ")]}"
        if ch == "," and depth == 0:
            params.append(cur.strip())
            cur = ""
        else:
            cur += ch
    out = []
    for p in params:
        if not p or p.startswith("self") or p.startswith("**"):
            continue
        name, _, default = p.partition(" = ")
        name = name.split(":")[0].strip()
        out.append((name, ast.literal_eval(default) if default else ...))
    return out


def test_joint_keywords_are_the_tables_in_the_stub_with_its_defaults():
    init = stub_parameters(stub_functions()["Joint.__init__"])
    table = {o["key"]: o["default"] for o in rows("joint")}
    assert {k for k, _ in init} == set(table), ({k for k, _ in init} ^ set(table))
    for key, default in init:
        expect = table[key]
        assert default == expect or (default is ... and expect is None), (key, default, expect)
    # The module's own list (its docstring) is the table's too.
    doc = impinge._impinge.Joint.__init__.__doc__
    listed = re.search(r"default\): ([a-z_, ]+)\.", doc).group(1)
    assert {x.strip() for x in listed.split(",")} == set(table)


# rom_limits, rom_map, plan and generated_hip take their keywords through the one path Joint() takes (**options ->
# the table's rows): the module's keyword set is the table's by construction; the stub's and the docstring's are
# checked against it, and a keyword of another use is refused naming the known ones.
@pytest.fixture(scope="module")
def small_joint():
    h = impinge.generated_hip(triangles=3000)
    return impinge.Joint(h["femur"], h["pelvis"], neutral="scan", precision=2.0)


@pytest.mark.parametrize("owner,method,use", [("Joint", "rom_limits", "rom_limits"), ("Joint", "rom_map", "rom_map"),
                                              ("Joint", "plan", "joint_plan"), ("", "generated_hip", "generated_hip")])
def test_keyword_functions_take_the_tables_keywords(owner, method, use, small_joint):
    table = {o["key"]: o["default"] for o in rows(use)}
    fn = getattr(getattr(impinge._impinge, owner) if owner else impinge._impinge, method)
    assert module_parameters(fn) == [] and "**kwargs" in fn.__doc__.splitlines()[0]
    stub = stub_parameters(stub_functions()[f"{owner}.{method}" if owner else method])
    assert dict(stub) == table and [k for k, _ in stub] == list(table), (stub, table)
    other = next(o["key"] for o in OPTIONS if use not in o["uses"])
    with pytest.raises(impinge.Error, match=f"{method}: unknown option '{other}' \\(options: "):
        if owner:
            fn(small_joint, **{other: 1})
        else:
            fn(**{other: 1})


FORMER_KEYS = [(old, o["key"]) for o in OPTIONS for old in o["old_keys"]]


@pytest.mark.parametrize("old,new", FORMER_KEYS)
def test_former_keys_still_work_with_a_warning(old, new, small_joint):
    """A renamed Python keyword (issue 78: keys carry their unit; --setup is --query-strategy) is accepted for one
    release with a DeprecationWarning naming its replacement; giving both is an error; a bad value is reported
    under the name given."""
    h = impinge.generated_hip(triangles=3000)
    with pytest.warns(DeprecationWarning, match=f"'{old}' is deprecated .* use '{new}'"):
        with pytest.raises(impinge.Error, match=rf"(^|[^\w]){old}(?!\w)"):  # the name given, not the new one
            impinge.Joint(h["femur"], h["pelvis"], neutral="scan", precision=2.0, **{old: -1.0 if old != "setup"
                                                                                  else "sometimes"})
    with pytest.raises(impinge.Error, match=f"give {new} or {old} \\(its former name\\), not both"):
        impinge.Joint(h["femur"], h["pelvis"], neutral="scan", **{old: 1.0, new: 1.0})


def test_former_keys_in_a_study_file_are_renamed_with_a_warning(tmp_path):
    path = tmp_path / "study.toml"
    path.write_text("subjects = [{generated = {}}]\n[joint]\nsparse = 40.0\n[[task]]\nkind = 'rom'\n"
                    "layered_spacing = 1.0\n")
    with pytest.warns(FutureWarning, match="joint.sparse: 'sparse' is deprecated"):
        study = spec.load_study(str(path))
    assert study["joint"] == {"sparse_region_mm": [40.0]} or study["joint"] == {"sparse_region_mm": 40.0}
    assert "layered_spacing_deg" in study["tasks"][0]["joint"]
    path.write_text("subjects = [{generated = {}}]\n[joint]\nsparse = 40.0\nsparse_region_mm = 1.0\n"
                    "[[task]]\nkind = 'rom'\n")
    with pytest.raises(spec.StudyError, match="give sparse_region_mm or sparse"):
        spec.load_study(str(path))


def test_committed_stub_is_the_generated_one():
    """The build writes impinge/__init__.pyi from the template and the table (python/gen_stub.py); the committed
    stub must be that file (regenerate it as gen_stub.py says)."""
    built = os.path.join(os.path.dirname(impinge.__file__), "__init__.pyi")
    assert os.path.exists(built), "the build did not generate the stub"
    committed = open(STUB).read()
    assert open(built).read() == committed, "python/impinge/__init__.pyi differs from the generated stub: run " \
        "PYTHONPATH=build/python /usr/bin/python3 python/gen_stub.py python/impinge/__init__.pyi.in " \
        "python/impinge/__init__.pyi"
    assert "@keywords" not in committed and "#@" not in committed


def test_stub_signatures_are_the_modules():
    """Every function and method of the extension has a stub entry with the same parameters and defaults."""
    stubs = stub_functions()
    checked = 0
    for owner, prefix in ((impinge._impinge, ""), (impinge._impinge.Joint, "Joint."), (impinge._impinge.Map, "Map.")):
        for name in dir(owner):
            obj = getattr(owner, name)
            if name.startswith("_") or not callable(obj) or isinstance(obj, type) or not obj.__doc__:
                continue
            if not obj.__doc__.startswith(name + "("):
                continue  # not a pybind11 function (an exception type, a property)
            assert prefix + name in stubs, f"the stub lacks {prefix + name}"
            if prefix + name == "load_mesh":  # the package's own load_mesh adds scale=
                continue
            if prefix + name in ("Joint.rom_limits", "Joint.rom_map", "Joint.plan", "generated_hip"):
                continue  # **options: the table's keywords, checked above
            stub = stub_parameters(stubs[prefix + name])
            assert module_parameters(obj) == stub, (prefix + name, module_parameters(obj), stub)
            checked += 1
    assert checked >= 15, checked


def test_study_keys_are_the_tables_and_documented():
    types = {"number": float, "integer": int, "flag": bool, "on_off": bool, "choice": str, "text": str,
             "numbers": list, "region": list}
    assert spec.JOINT_KEYS == {o["key"]: types[o["type"]] for o in rows("study")}
    assert spec.KIND_KEYS["rom"] == {o["key"]: o["default"] for o in rows("rom_limits")}
    assert spec.KIND_KEYS["envelope"] == {o["key"]: o["default"] for o in rows("rom_map")}
    assert spec.KIND_KEYS["plan"] == {o["key"]: o["default"] for o in rows("joint_plan")}
    doc = open(STUDIES_DOC).read()
    missing = [k for k in list(spec.JOINT_KEYS) + list(spec.KIND_KEYS["rom"]) + list(spec.KIND_KEYS["envelope"])
               + list(spec.KIND_KEYS["plan"])
               if f"`{k}`" not in doc]
    assert not missing, f"docs/studies.md does not name {missing}"


def test_bad_values_name_the_option_the_value_and_the_range():
    with pytest.raises(impinge.Error, match=r"max_radius_mm: -1 mm is outside the valid range \[0, 10000\] mm"):
        impinge.Joint(subject="x.json", max_radius_mm=-1)
    with pytest.raises(impinge.Error, match=r"layers: 2.5 is not a whole number"):
        impinge.Joint(subject="x.json", layers=2.5)
    with pytest.raises(impinge.Error, match=r"mode: 'fast' is not one of exact, linear"):
        impinge.Joint(subject="x.json", mode="fast")
    with pytest.raises(impinge.Error, match=r"cam_mm: nan is not a finite number"):
        impinge.generated_hip(cam_mm=float("nan"))
    with pytest.raises(impinge.Error, match=r"triangles: 2000000000 is outside the valid range"):
        impinge.generated_hip(triangles=2_000_000_000)
    r = subprocess.run([CLI, "rom", "--subject", "x.json", "--step", "0", "--out", "/tmp/never"],
                       capture_output=True, text=True)
    assert r.returncode == 2 and "--step: 0 deg is outside the valid range [0.01, 90] deg" in r.stderr, r.stderr
    r = subprocess.run([CLI, "generate", "--cam", "nan", "--out", "/tmp/never"], capture_output=True, text=True)
    assert r.returncode == 2 and "--cam: 'nan' is not a finite number" in r.stderr, r.stderr


def test_the_pivot_is_named_apart_from_the_head_centre(small_joint):
    """Joint.pivot (summary.json's pivot_mm): the point the femur turns about. A scan-neutral generated hip turns
    about its femoral head centre, so the pivot is `cor`, and the posed femur keeps that point fixed (femur_pose's
    (R, t): V -> (V - cor) R^T + cor + t)."""
    import numpy as np
    assert small_joint.setup["joint_centre"] == "femoral-head"
    np.testing.assert_array_equal(small_joint.pivot, small_joint.cor)
    np.testing.assert_array_equal(small_joint.setup["pivot_mm"], small_joint.cor)
    R, t = small_joint.femur_pose(40, 10, 20)
    c = np.asarray(small_joint.pivot)
    np.testing.assert_allclose((c - small_joint.cor) @ np.asarray(R).T + small_joint.cor + t, c, atol=1e-9)
