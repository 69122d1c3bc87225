// Atomic output: a file is written to a temporary name beside it and renamed into place, so a
// crash never leaves a half-written file that looks whole. The output folder's lock, manifest
// and consistent set of result files build on this (pipeline/store/output_set.h).
#pragma once

#include <string>

namespace bifilar {

// The temporary name WriteFileAtomically uses for `path`: "<path>.tmp.<pid>".
std::string AtomicTemporaryName(const std::string& path);

// Writes `text` to `path` atomically (temporary file in the same folder, then rename); creates
// missing parent folders. Throws UserError naming the path on failure, and before writing
// anything when `path` exists and is not a regular file (a folder, device, FIFO or socket; a
// symbolic link counts as what it points to).
void WriteFileAtomically(const std::string& path, const std::string& text);

}  // namespace bifilar
