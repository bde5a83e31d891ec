// The impinge CLI's allocator: jemalloc when CMake links it (IMPINGE_WITH_JEMALLOC; see IMPINGE_JEMALLOC in
// CMakeLists.txt), otherwise the C library's.
//
// Why jemalloc: a run's set-up frees much of what it allocates (a body's rasteriser cones, a hierarchy's
// scratch) on one thread while the next allocation happens on another; with one arena for every thread the
// freed pages are used again instead of new ones being faulted in (below).
//
// Huge pages (issue 52): the CLI asks jemalloc for transparent huge pages (thp:always; MALLOC_CONF=thp:default
// leaves them to the system's setting, /sys/kernel/mm/transparent_hugepage/enabled). Which is faster depends on the
// virtual machine's state, and has been measured both ways on the 2-core VM, which reports freed memory to its host
// (virtio free page reporting: free 2 MiB blocks some 2 s after they are freed), so that a page the guest hands out
// may have to be faulted in by the host as well:
// - a VM whose memory the host has backed for a while (earlier sessions; lhdl-ct one pose, `impinge distance`,
//   alternated, medians of 3 to 10): 2.5 s after the last process 192 ms with huge pages against 131 ms without;
//   right after Open3D's job 123 against 122 ms; the hip subdivided 4x right after Open3D's job 623 against 480 ms.
// - a fresh VM (session 69, `tools/ab-cli`, medians of 4 to 6): every 4 KiB page fault costs some 11 us (a run
//   takes 21,600 of them, 0.17-0.20 s of kernel time in a 0.29 s run), and with huge pages 2,600-3,000:
//   one pose 2.5 s after the last process 307 -> 235 ms, right after Open3D's job 310 -> 213 ms (Open3D 959 ms),
//   back to back 290 -> 170 ms; the hip subdivided 4x after a pause 1,219 -> 747 ms; `impinge rom` 1,264 -> 1,132
//   ms; a 1,000-frame motion 2.40 -> 2.26 s.
// Huge pages lose up to 1.5x in the first state and gain up to 1.7x in the second; on a machine without free page
// reporting (bare metal) a huge page is one fault instead of 512. They are asked for; the peak resident memory
// grows from some 78 to 106 MB (lhdl-ct, one pose).

#include "allocator.hpp"

#ifdef IMPINGE_WITH_JEMALLOC
#include <jemalloc/jemalloc.h>

// jemalloc(3): "malloc_conf: a string embedded in the program"; the MALLOC_CONF environment variable,
// read after it, overrides it.
// thp:always: above. narenas:1 and oversize_threshold:0 (issue 52): one arena for every thread, and no separate arena for
// allocations above 8 MiB, so that memory one thread frees (a body's build, the rasteriser's cones, a
// hierarchy's scratch) is reused by the next allocation on any thread instead of new pages being faulted in
// (jemalloc gives each thread one of 4 x cores arenas, and returns the oversize arena's memory to the system
// at once). lhdl-ct, one pose (`impinge distance`, then with huge pages): page faults 8,850 -> 3,270, kernel
// time 37 -> 25 ms, whole run 130 -> 119 ms (medians of 15); alternated with Open3D's job as
// benchmarks/whole_process.py runs them, 134 -> 120 ms (medians of 20). Motions and ROM searches allocate
// little per frame: unchanged within their spread.
extern "C" {
const char* malloc_conf = "narenas:1,oversize_threshold:0,thp:always";
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
