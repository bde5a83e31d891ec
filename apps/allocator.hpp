// The impinge CLI's memory allocator, as summary.json records it.
#pragma once

#include <string>

namespace impinge {

/// What serves the CLI's allocations: "jemalloc VERSION, transparent huge pages: MODE" when the CLI
/// is linked with jemalloc (CMake option IMPINGE_JEMALLOC, apps/allocator.cpp), otherwise "C library".
/// MODE is jemalloc's opt.thp as in force: "default" (the system's transparent huge page setting decides)
/// unless the MALLOC_CONF environment variable overrides it (e.g. MALLOC_CONF=thp:always). Never throws.
std::string allocator_description();

}  // namespace impinge
