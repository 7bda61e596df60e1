// Provenance of every output: project version and git revision of the build.
#pragma once

namespace knit {
const char* project_version();
/// `git describe --always --dirty` of the source tree at build time, or "unknown".
const char* git_revision();
}  // namespace knit
