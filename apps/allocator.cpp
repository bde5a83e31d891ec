// The impinge CLI's allocator: jemalloc with transparent huge pages when CMake links it
// (IMPINGE_WITH_JEMALLOC; see IMPINGE_JEMALLOC in CMakeLists.txt), otherwise the C library's.
//
// Why: one run of impinge rom touches 150-250 MB of new memory within a second (two 0.1-deg maps of
// 26 MB each, layered maps, the closest-point and ray-casting hierarchies). In 4 KiB pages that is
// some 45,000 page faults; on a virtual machine each costs several microseconds, 15-25 % of the run.
// In 2 MiB transparent huge pages it is a few thousand. The kernel's default THP mode
// ("madvise") gives huge pages only to memory marked MADV_HUGEPAGE, which glibc's malloc does only
// under an environment tunable; jemalloc marks its own mappings when its option thp is "always"
// (jemalloc(3), "opt.thp"), and reads its options from the program's malloc_conf at start-up.

#include "allocator.hpp"

#ifdef IMPINGE_WITH_JEMALLOC
#include <jemalloc/jemalloc.h>

// jemalloc(3): "malloc_conf: a string embedded in the program"; the MALLOC_CONF environment variable,
// read after it, overrides it. metadata_thp: jemalloc's own bookkeeping in huge pages too.
// narenas:1 and oversize_threshold:0 (issue 52): one arena for every thread, and no separate arena for
// allocations above 8 MiB, so that memory one thread frees (a body's build, the rasteriser's cones, a
// hierarchy's scratch) is reused by the next allocation on any thread instead of new pages being faulted in
// (jemalloc gives each thread one of 4 x cores arenas, and returns the oversize arena's memory to the system
// at once). lhdl-ct, one pose (`impinge distance`): page faults 8,850 -> 3,270, kernel time 37 -> 25 ms,
// whole run 130 -> 119 ms (medians of 15); alternated with Open3D's job as benchmarks/whole_process.py runs
// them, 134 -> 120 ms (medians of 20). Motions and ROM searches allocate little per frame: unchanged within their spread.
extern "C" {
const char* malloc_conf = "thp:always,metadata_thp:always,narenas:1,oversize_threshold:0";
}
#endif

namespace impinge {

std::string allocator_description() {
#ifndef IMPINGE_WITH_JEMALLOC
  return "C library";
#else
  const char* version = nullptr;
  const char* thp = nullptr;
  std::size_t size = sizeof(const char*);
  if (mallctl("version", static_cast<void*>(&version), &size, nullptr, 0) != 0 || version == nullptr)
    return "jemalloc";
  size = sizeof(const char*);
  if (mallctl("opt.thp", static_cast<void*>(&thp), &size, nullptr, 0) != 0 || thp == nullptr)
    return std::string("jemalloc ") + version;
  return std::string("jemalloc ") + version + ", transparent huge pages: " + thp;
#endif
}

}  // namespace impinge
