"""impinge.build_info() and impinge.machine_info(): what every experiment's meta.json records (provenance.hpp),
checked against the machine's own files read here independently."""
import os

import impinge

KEYS = ["cpu_model", "cpu_family", "cpu_model_number", "cpu_stepping", "cpu_mhz", "l2_cache", "l3_cache",
        "logical_cpus", "sockets", "physical_cores", "smt", "thread_siblings", "memory_gib", "hypervisor", "os_kernel"]


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


def test_machine_info_gives_the_cpu_topology_as_sysfs_and_lscpu_do():
    # Read here independently: every online CPU's topology files; lscpu -p (when present) agrees on the core count.
    import glob
    import re
    import shutil
    import subprocess
    m = impinge.machine_info()
    dirs = [d for d in glob.glob("/sys/devices/system/cpu/cpu*") if re.fullmatch(r"cpu\d+", os.path.basename(d))
            and os.path.exists(os.path.join(d, "topology", "thread_siblings_list"))]
    if not dirs:
        assert m["smt"] == "unknown"
        return

    def read(d, f):
        with open(os.path.join(d, "topology", f)) as fh:
            return fh.read().strip()
    cores = {(read(d, "physical_package_id"), read(d, "core_id")) for d in dirs}
    groups = {read(d, "thread_siblings_list") for d in dirs}
    assert m["physical_cores"] == str(len(cores))
    assert m["sockets"] == str(len({c[0] for c in cores}))
    assert m["smt"] == ("yes" if len(cores) < len(dirs) else "no")
    assert sorted(m["thread_siblings"].split(" | ")) == sorted(groups)
    if shutil.which("lscpu"):
        rows = [line.split(",") for line in subprocess.run(["lscpu", "-p=CORE,SOCKET"], capture_output=True,
                                                             text=True).stdout.splitlines() if line[:1].isdigit()]
        assert len({tuple(r) for r in rows}) == len(cores)
