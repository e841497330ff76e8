#pragma once
// FNV-1a, 64 bit: the one fingerprint hash of the project (checkpoints, engine/checkpoint.cpp;
// the journals of capacity and sweep, engine/journal.hpp). Not cryptographic: it tells a
// file written for another model or settings from ours.

#include <cstdint>
#include <cstdio>
#include <string>
#include <type_traits>
#include <vector>

namespace voussoir {

// Values and arrays as bytes into Sink::bytes(p, n): the hash below and the checkpoint writer
// (engine/checkpoint.cpp) take the same byte stream. An array is its size (u64) then its items.
template <class Sink>
struct ByteWriter {
  template <class T>
  void value(const T& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    static_cast<Sink*>(this)->bytes(&v, sizeof v);
  }
  template <class T>
  void array(const std::vector<T>& v) {
    value<std::uint64_t>(v.size());
    if (!v.empty()) static_cast<Sink*>(this)->bytes(v.data(), v.size() * sizeof(T));
  }
};

struct Fnv : ByteWriter<Fnv> {
  std::uint64_t h = 0xcbf29ce484222325ull;
  void bytes(const void* p, std::size_t n) {
    const auto* c = static_cast<const unsigned char*>(p);
    for (std::size_t k = 0; k < n; ++k) {
      h ^= c[k];
      h *= 0x100000001b3ull;
    }
  }
  void text(const std::string& s) {
    value<std::uint64_t>(s.size());
    bytes(s.data(), s.size());
  }
  // 16 hex digits.
  std::string hex() const {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(h));
    return buf;
  }
};

}  // namespace voussoir
