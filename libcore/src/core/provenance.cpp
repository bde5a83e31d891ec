#include "impinge/core/provenance.hpp"

#include <sys/utsname.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>

#ifndef IMPINGE_COMPILER
#define IMPINGE_COMPILER "unknown"
#endif

namespace impinge {
namespace {

// The "key<tabs>: value" fields of `path` up to its first blank line (for /proc/cpuinfo: the first CPU), each key's
// first value, surrounding blanks removed.
std::map<std::string, std::string> proc_fields(const char* path) {
  std::map<std::string, std::string> fields;
  std::ifstream in(path);
  std::string line;
  auto trim = [](const std::string& t) {
    const auto b = t.find_first_not_of(" \t"), e = t.find_last_not_of(" \t");
    return b == std::string::npos ? std::string() : t.substr(b, e - b + 1);
  };
  while (std::getline(in, line) && !trim(line).empty()) {
    const auto colon = line.find(':');
    if (colon != std::string::npos) fields.emplace(trim(line.substr(0, colon)), trim(line.substr(colon + 1)));
  }
  return fields;
}

std::string or_unknown(std::string s) { return s.empty() ? std::string("unknown") : s; }

std::string field(const std::map<std::string, std::string>& fields, const std::string& key) {
  const auto it = fields.find(key);
  return or_unknown(it == fields.end() ? std::string() : it->second);
}

std::string first_line(const std::string& path) {
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);
  return line;
}

// The size of cpu0's cache of `level` (unified or data), e.g. "2048K", from sysfs.
std::string cache_size(int level) {
  for (int index = 0; index < 8; ++index) {
    const std::string dir = "/sys/devices/system/cpu/cpu0/cache/index" + std::to_string(index) + "/";
    const std::string l = first_line(dir + "level");
    if (l.empty()) break;
    if (std::to_string(level) != l || first_line(dir + "type") == "Instruction") continue;
    return first_line(dir + "size");
  }
  return {};
}

// The CPU topology from sysfs (/sys/devices/system/cpu/cpuN/topology): the sockets (distinct physical_package_id),
// the physical cores (distinct package and core_id pairs), whether any core runs more than one logical CPU (SMT:
// a thread_siblings_list of more than one CPU) and the sibling groups themselves ("0 | 1": two cores of one
// thread each; "0-1": one core of two threads). Empty values where sysfs does not say.
struct Topology {
  std::string sockets, cores, smt, siblings;
};

Topology cpu_topology() {
  namespace fs = std::filesystem;
  std::set<std::string> packages, groups;
  std::set<std::pair<std::string, std::string>> cores;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator("/sys/devices/system/cpu", ec)) {
    const std::string name = entry.path().filename().string();
    if (name.size() < 4 || name.compare(0, 3, "cpu") != 0 ||
        name.find_first_not_of("0123456789", 3) != std::string::npos)
      continue;
    const std::string dir = entry.path().string() + "/topology/";
    const std::string package = first_line(dir + "physical_package_id"), core = first_line(dir + "core_id");
    const std::string group = first_line(dir + "thread_siblings_list");
    if (package.empty() || core.empty() || group.empty()) continue;  // offline, or no topology exposed
    packages.insert(package);
    cores.emplace(package, core);
    groups.insert(group);
  }
  Topology t;
  if (groups.empty()) return t;
  t.sockets = std::to_string(packages.size());
  t.cores = std::to_string(cores.size());
  bool smt = false;
  for (const auto& g : groups) {
    smt = smt || g.find_first_of(",-") != std::string::npos;
    t.siblings += (t.siblings.empty() ? "" : " | ") + g;
  }
  t.smt = smt ? "yes" : "no";
  return t;
}

}  // namespace

std::string compiler_description() { return IMPINGE_COMPILER; }

std::vector<std::pair<std::string, std::string>> machine_description() {
  std::vector<std::pair<std::string, std::string>> m;
  const auto cpu = proc_fields("/proc/cpuinfo");
  m.emplace_back("cpu_model", field(cpu, "model name"));
  m.emplace_back("cpu_family", field(cpu, "cpu family"));
  m.emplace_back("cpu_model_number", field(cpu, "model"));
  m.emplace_back("cpu_stepping", field(cpu, "stepping"));
  m.emplace_back("cpu_mhz", field(cpu, "cpu MHz"));
  m.emplace_back("l2_cache", or_unknown(cache_size(2)));
  m.emplace_back("l3_cache", or_unknown(cache_size(3)));
  const long cpus = sysconf(_SC_NPROCESSORS_ONLN);
  m.emplace_back("logical_cpus", cpus > 0 ? std::to_string(cpus) : std::string("unknown"));
  const Topology topology = cpu_topology();
  m.emplace_back("sockets", or_unknown(topology.sockets));
  m.emplace_back("physical_cores", or_unknown(topology.cores));
  m.emplace_back("smt", or_unknown(topology.smt));
  m.emplace_back("thread_siblings", or_unknown(topology.siblings));
  std::string memory = "unknown";
  const std::string kb = field(proc_fields("/proc/meminfo"), "MemTotal");  // "24684100 kB"
  double kib = 0;
  if (std::sscanf(kb.c_str(), "%lf", &kib) == 1 && kib > 0) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.1f", kib / (1024.0 * 1024.0));
    memory = buf;
  }
  m.emplace_back("memory_gib", memory);
  const auto flags = cpu.find("flags");
  m.emplace_back("hypervisor", flags == cpu.end() ? std::string("unknown")
                               : (" " + flags->second + " ").find(" hypervisor ") != std::string::npos ? "yes"
                                                                                                       : "no");
  utsname u{};
  m.emplace_back("os_kernel", uname(&u) == 0 ? std::string(u.sysname) + " " + u.release : std::string("unknown"));
  return m;
}

}  // namespace impinge
