"""tools/long-functions (issue 78, part 4) catches what it is for: a planted function over 80 lines and a file over
550 fail --check; the same function with a '// long: <reason>' comment above it passes, listed as allowed."""
import os
import subprocess

TOOL = os.path.join(os.path.dirname(__file__), "..", "tools", "long-functions")


def run(root):
    return subprocess.run(["bash", TOOL, "--check", str(root)], capture_output=True, text=True)


def plant(root, body_lines, comment="", extra_lines=0):
    d = root / "libcore" / "src"
    d.mkdir(parents=True, exist_ok=True)
    (root / "apps").mkdir(exist_ok=True)
    body = "".join(f"  x += {i};\n" for i in range(body_lines))
    pad = "".join("// pad\n" for _ in range(extra_lines))
    (d / "a.cpp").write_text(f"{comment}int f(int x) {{\n{body}  return x;\n}}\n{pad}")


def test_a_function_over_80_lines_fails(tmp_path):
    plant(tmp_path, 85)
    r = run(tmp_path)
    assert r.returncode == 1 and "OVER" in r.stdout and " f" in r.stdout, r.stdout + r.stderr


def test_a_stated_reason_allows_it(tmp_path):
    plant(tmp_path, 85, comment="// long: a table read top to bottom\n")
    r = run(tmp_path)
    assert r.returncode == 0 and "allowed" in r.stdout, r.stdout + r.stderr


def test_short_functions_pass_and_a_long_file_fails(tmp_path):
    plant(tmp_path, 10)
    assert run(tmp_path).returncode == 0
    plant(tmp_path, 10, extra_lines=560)
    r = run(tmp_path)
    assert r.returncode == 1 and "FILE" in r.stdout, r.stdout
