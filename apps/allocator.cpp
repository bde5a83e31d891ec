// The impinge CLI's allocator: jemalloc when CMake links it (IMPINGE_WITH_JEMALLOC; see IMPINGE_JEMALLOC in
// CMakeLists.txt), otherwise the C library's.
//
// Why jemalloc: a run's set-up frees much of what it allocates (a body's rasteriser cones, a hierarchy's
// scratch) on one thread while the next allocation happens on another; with one arena for every thread the
// freed pages are used again instead of new ones being faulted in (below).
//
// Huge pages (issue 52): the CLI used to ask jemalloc for transparent huge pages (thp:always). They cut a run's page
// faults eightfold (lhdl-ct, one pose: some 21,000 -> 2,600), but on a virtual machine that reports freed memory to
// its host (virtio free page reporting, which reports free 2 MiB blocks some 2 s after they are freed) a huge page
// is likely to be such a block, and touching it faults in the host as well. Measured on the 2-core VM (lhdl-ct, the
// CLI built both ways, alternated, medians of 3 to 10): one pose (`impinge distance`) 2.5 s after the last process
// 192 ms with huge pages against 131 ms without; right after Open3D's job (benchmarks/whole_process.py's order)
// 123 ms (quartiles 111-139) against 122 ms (119-124); `impinge rom` 750 against 662 ms after a pause, 617 against
// 650 ms back to back; a 1,000-frame motion 1.68 against 1.59 s and 1.56 against 1.58 s. Without them a run costs
// about the same whether the machine was idle or not, and a user's run usually follows a pause. So thp is left at
// jemalloc's "default": the system's setting (/sys/kernel/mm/transparent_hugepage/enabled) decides;
// MALLOC_CONF=thp:always asks for them.

#include "allocator.hpp"

#ifdef IMPINGE_WITH_JEMALLOC
#include <jemalloc/jemalloc.h>

// jemalloc(3): "malloc_conf: a string embedded in the program"; the MALLOC_CONF environment variable,
// read after it, overrides it.
// narenas:1 and oversize_threshold:0 (issue 52): one arena for every thread, and no separate arena for
// allocations above 8 MiB, so that memory one thread frees (a body's build, the rasteriser's cones, a
// hierarchy's scratch) is reused by the next allocation on any thread instead of new pages being faulted in
// (jemalloc gives each thread one of 4 x cores arenas, and returns the oversize arena's memory to the system
// at once). lhdl-ct, one pose (`impinge distance`, then with huge pages): page faults 8,850 -> 3,270, kernel
// time 37 -> 25 ms, whole run 130 -> 119 ms (medians of 15); alternated with Open3D's job as
// benchmarks/whole_process.py runs them, 134 -> 120 ms (medians of 20). Motions and ROM searches allocate
// little per frame: unchanged within their spread.
extern "C" {
const char* malloc_conf = "narenas:1,oversize_threshold:0";
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
