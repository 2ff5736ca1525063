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

/// A run's outputs appear together or not at all. While a group is open on
/// this thread, every atomic write of the library (meshes, volumes, images,
/// JSON, an OBJ's MTL and PNG) stops at its complete temporary file;
/// commit() renames them all over their names, in the order they were
/// written (one rename each, so the window in which only some are there is
/// a few system calls long). A group destroyed without commit() removes its
/// temporaries, and a killed process leaves only temporaries, which the next
/// write of the same name removes. Groups do not nest.
class OutputGroup {
 public:
  OutputGroup();
  ~OutputGroup();
  OutputGroup(const OutputGroup&) = delete;
  OutputGroup& operator=(const OutputGroup&) = delete;
  /// Renames every pending temporary over its name; throws InputError naming
  /// the first that fails (those renamed before it stay).
  void commit();
  /// commit() of the group open on this thread, if any (a command whose
  /// verdict is a failure still delivers its report).
  static void commit_open();
};

/// Installs SIGINT, SIGTERM and SIGHUP handlers that remove the temporaries
/// of the writes in progress (and of a group not yet committed), then end the
/// process by the same signal. SIGKILL cannot be caught: the next write of
/// the same name removes what it leaves.
void remove_temporaries_on_signals();

}  // namespace voxpress
