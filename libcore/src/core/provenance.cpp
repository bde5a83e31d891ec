#include "impinge/core/provenance.hpp"

#include <sys/utsname.h>
#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <sstream>

#ifndef IMPINGE_COMPILER
#define IMPINGE_COMPILER "unknown"
#endif

namespace impinge {
namespace {

// The text after "key<tabs>: " on the first line of `path` that starts with `key` followed by
// whitespace or ':', or "" when there is none.
std::string proc_field(const char* path, const std::string& key) {
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind(key, 0) != 0 || line.size() == key.size()) continue;
    const char next = line[key.size()];
    if (next != ' ' && next != '\t' && next != ':') continue;
    const auto colon = line.find(':');
    if (colon == std::string::npos) continue;
    std::string v = line.substr(colon + 1);
    const auto b = v.find_first_not_of(" \t");
    return b == std::string::npos ? std::string() : v.substr(b);
  }
  return {};
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

std::string or_unknown(std::string s) { return s.empty() ? std::string("unknown") : s; }

}  // namespace

std::string compiler_description() { return IMPINGE_COMPILER; }

std::vector<std::pair<std::string, std::string>> machine_description() {
  std::vector<std::pair<std::string, std::string>> m;
  m.emplace_back("cpu_model", or_unknown(proc_field("/proc/cpuinfo", "model name")));
  m.emplace_back("cpu_family", or_unknown(proc_field("/proc/cpuinfo", "cpu family")));
  m.emplace_back("cpu_model_number", or_unknown(proc_field("/proc/cpuinfo", "model")));
  m.emplace_back("cpu_stepping", or_unknown(proc_field("/proc/cpuinfo", "stepping")));
  m.emplace_back("cpu_mhz", or_unknown(proc_field("/proc/cpuinfo", "cpu MHz")));
  m.emplace_back("l2_cache", or_unknown(cache_size(2)));
  m.emplace_back("l3_cache", or_unknown(cache_size(3)));
  const long cpus = sysconf(_SC_NPROCESSORS_ONLN);
  m.emplace_back("logical_cpus", cpus > 0 ? std::to_string(cpus) : std::string("unknown"));
  std::string memory = "unknown";
  const std::string kb = proc_field("/proc/meminfo", "MemTotal");  // "24684100 kB"
  double kib = 0;
  if (std::sscanf(kb.c_str(), "%lf", &kib) == 1 && kib > 0) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.1f", kib / (1024.0 * 1024.0));
    memory = buf;
  }
  m.emplace_back("memory_gib", memory);
  const std::string flags = proc_field("/proc/cpuinfo", "flags");
  m.emplace_back("hypervisor", flags.empty()                                                   ? std::string("unknown")
                               : (" " + flags + " ").find(" hypervisor ") != std::string::npos ? "yes"
                                                                                               : "no");
  utsname u{};
  m.emplace_back("os_kernel", uname(&u) == 0 ? std::string(u.sysname) + " " + u.release : std::string("unknown"));
  return m;
}

}  // namespace impinge
