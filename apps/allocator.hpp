// The impinge CLI's memory allocator, as summary.json records it.
#pragma once

#include <string>

namespace impinge {

/// What serves the CLI's allocations: "jemalloc VERSION, transparent huge pages: MODE" when the CLI
/// is linked with jemalloc (CMake option IMPINGE_JEMALLOC, apps/allocator.cpp), otherwise "C library".
/// MODE is jemalloc's opt.thp as in force: "always" (transparent huge pages asked for, apps/allocator.cpp says
/// why) unless the MALLOC_CONF environment variable overrides it (MALLOC_CONF=thp:default leaves them to the
/// system's setting). Never throws.
std::string allocator_description();

}  // namespace impinge
