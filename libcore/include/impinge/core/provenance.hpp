#pragma once
/// @file provenance.hpp
/// Where a result came from, for the meta data every experiment writes (meta.json) and for
/// benchmark contexts: the compiler that built the library and what the machine says about itself.
/// One source for the C++ drivers, the Python drivers (`impinge.build_info()`,
/// `impinge.machine_info()`) and the benchmarks, so every meta.json carries the same fields
/// (issue 51: "the full CPU model, clock and memory recorded where the machine exposes them").

#include <string>
#include <utility>
#include <vector>

namespace impinge {

/// The compiler that built libcore: CMake's compiler id and version, e.g. "GNU 12.2.0".
std::string compiler_description();

/// What this machine exposes about itself, as (key, value) pairs in a fixed order, every key always
/// present ("unknown" where the machine does not say):
///   cpu_model (/proc/cpuinfo "model name"; a virtual machine may give only the vendor's family
///   name, e.g. "AMD EPYC"), cpu_family, cpu_model_number, cpu_stepping (cpuinfo: with the vendor
///   they name the microarchitecture), cpu_mhz (cpuinfo "cpu MHz" of the first CPU, the clock the
///   kernel reports), l2_cache and l3_cache (sysfs cache index of cpu0, e.g. "2048K"),
///   logical_cpus (online CPUs), sockets and physical_cores (sysfs topology: distinct physical_package_id, and
///   package and core_id pairs), smt ("yes" when a core runs more than one logical CPU, "no" when every logical
///   CPU is a core of its own: whether two threads share a core matters to a 2-thread scaling, issue 82),
///   thread_siblings (sysfs thread_siblings_list of each core, "0 | 1": two cores; "0-1": one core, two threads;
///   in a virtual machine, the topology its hypervisor exposes),
///   memory_gib (/proc/meminfo MemTotal, GiB, 1 decimal), hypervisor
///   ("yes" when cpuinfo's flags hold "hypervisor": a virtual machine, "no" otherwise),
///   os_kernel (uname: system and release).
/// Reads only; never throws (a file it cannot read gives "unknown").
std::vector<std::pair<std::string, std::string>> machine_description();

}  // namespace impinge
