"""impinge.build_info() and impinge.machine_info(): what every experiment's meta.json records (provenance.hpp),
checked against the machine's own files read here independently."""
import os

import impinge

KEYS = ["cpu_model", "cpu_family", "cpu_model_number", "cpu_stepping", "cpu_mhz", "l2_cache", "l3_cache",
        "logical_cpus", "memory_gib", "hypervisor", "os_kernel"]


def cpuinfo(key):
    with open("/proc/cpuinfo") as f:
        for line in f:
            name, _, value = line.partition(":")
            if name.strip() == key:
                return value.strip()
    return "unknown"


def test_build_info_names_the_version_compiler_and_kernels():
    b = impinge.build_info()
    assert sorted(b) == ["compiler", "kernels", "version"]
    assert b["version"] == impinge.__version__
    assert b["compiler"].split()[0] in ("GNU", "Clang") and any(c.isdigit() for c in b["compiler"])
    assert b["kernels"].startswith("rasteriser ")


def test_machine_info_has_every_key_in_order_and_agrees_with_the_machines_files():
    m = impinge.machine_info()
    assert list(m) == KEYS
    assert all(isinstance(v, str) and v for v in m.values())
    if not os.path.exists("/proc/cpuinfo"):
        return
    assert m["cpu_model"] == cpuinfo("model name")
    assert m["cpu_family"] == cpuinfo("cpu family")
    assert m["cpu_model_number"] == cpuinfo("model")  # not "model name": the key is matched whole
    assert m["hypervisor"] == ("yes" if "hypervisor" in cpuinfo("flags").split() else "no")
    assert m["logical_cpus"] == str(os.sysconf("SC_NPROCESSORS_ONLN"))
    with open("/proc/meminfo") as f:
        kib = next(float(line.split()[1]) for line in f if line.startswith("MemTotal:"))
    assert m["memory_gib"] == f"{kib / 1024 ** 2:.1f}"
    assert m["os_kernel"] == f"{os.uname().sysname} {os.uname().release}"
