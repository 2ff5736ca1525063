// A bounds-checked little-endian reader over a byte buffer (private). Every
// read past the end throws InputError(path, "truncated ...").
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "voxpress/core/error.h"

namespace voxpress::detail {

class ByteCursor {
 public:
  ByteCursor(const std::string& path, const std::vector<std::byte>& data, size_t begin, size_t end)
      : path_(path), data_(data), pos_(begin), end_(end) {}

  size_t pos() const { return pos_; }
  size_t end() const { return end_; }
  size_t left() const { return end_ - pos_; }
  void need(size_t n, const char* what) const {
    if (n > left()) throw InputError(path_, std::string("truncated ") + what);
  }
  void skip(size_t n, const char* what) {
    need(n, what);
    pos_ += n;
  }
  void seek(size_t p, const char* what) {
    if (p > end_) throw InputError(path_, std::string("truncated ") + what);
    pos_ = p;
  }
  uint8_t u8(const char* what) {
    need(1, what);
    return uint8_t(data_[pos_++]);
  }
  uint32_t u32(const char* what) {
    need(4, what);
    uint32_t v;
    std::memcpy(&v, data_.data() + pos_, 4);
    pos_ += 4;
    return v;  // little-endian hosts only (checked at build time in vox.cpp)
  }
  int32_t i32(const char* what) { return int32_t(u32(what)); }
  float f32(const char* what) {
    const uint32_t b = u32(what);
    float f;
    std::memcpy(&f, &b, 4);
    return f;
  }
  std::string text(size_t n, const char* what) {
    need(n, what);
    std::string s(reinterpret_cast<const char*>(data_.data() + pos_), n);
    pos_ += n;
    return s;
  }

 private:
  const std::string& path_;
  const std::vector<std::byte>& data_;
  size_t pos_, end_;
};

}  // namespace voxpress::detail
