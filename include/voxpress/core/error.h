// voxpress/core/error.h — the exceptions voxpress throws.
//
// Library code never prints and never exits: it throws one of these at the
// boundary (readers, writers, option checks) and asserts inside algorithms.
// Only the CLI's main() catches, prints one line and maps the type to an exit
// code (see apps/voxpress/main.cpp and docs/ARCHITECTURE.md):
//   InputError  -> 1   a file is missing, malformed, truncated or unsupported
//   LimitError  -> 1   a resource limit (memory cap, index range) would be exceeded
//   UsageError  -> 2   contradictory or invalid options
//   anything else -> 3 internal error (a bug)
#pragma once

#include <stdexcept>
#include <string>

namespace voxpress {

/// Base of every voxpress exception. what() is one line, ready to print.
class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Bad input data. what() is "<path>: <problem>" when a path is known.
class InputError : public Error {
 public:
  InputError(const std::string& path, const std::string& problem)
      : Error(path.empty() ? problem : path + ": " + problem), path_(path), problem_(problem) {}
  const std::string& path() const { return path_; }
  const std::string& problem() const { return problem_; }

 private:
  std::string path_;
  std::string problem_;
};

/// A resource limit would be exceeded (checked before allocating).
class LimitError : public InputError {
 public:
  using InputError::InputError;
};

/// Invalid or contradictory options.
class UsageError : public Error {
 public:
  using Error::Error;
};

}  // namespace voxpress
