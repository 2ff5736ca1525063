// voxpress/io/atomic_file.h — write a file so that it appears complete or not at all.
#pragma once

#include <functional>
#include <ostream>
#include <string>

namespace voxpress {

/// Writes `path` through a temporary file in the same folder, renamed over
/// `path` only once `write` returned and the stream is good. If `write`
/// throws (or the process dies), `path` is untouched. Throws InputError when
/// the folder does not exist or the disk is full.
void write_file_atomically(const std::string& path, const std::function<void(std::ostream&)>& write);

}  // namespace voxpress
