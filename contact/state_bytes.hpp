#pragma once
// The opaque bytes of the contact systems' checkpoint state (ContactSystem::save_state and the
// rigid blocks' RigidContact::save_state): values and arrays in native byte order, an array as
// its length (uint64) then its elements.

#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

namespace voussoir {

inline void put_bytes(std::vector<char>& out, const void* p, std::size_t n) {
  const std::size_t at = out.size();
  out.resize(at + n);
  if (n > 0) std::memcpy(out.data() + at, p, n);
}
template <class T>
void put(std::vector<char>& out, const T& v) {
  put_bytes(out, &v, sizeof v);
}
template <class T>
void put_array(std::vector<char>& out, const std::vector<T>& v) {
  put<std::uint64_t>(out, v.size());
  put_bytes(out, v.data(), v.size() * sizeof(T));
}

// Reads what put and put_array wrote; throws std::runtime_error("contact state: ...") on
// truncated bytes.
struct StateReader {
  const std::vector<char>& in;
  std::size_t pos = 0;
  [[noreturn]] static void fail(const std::string& why) {
    throw std::runtime_error("contact state: " + why);
  }
  template <class T>
  T get() {
    T v{};
    if (sizeof v > in.size() - pos) fail("truncated");
    std::memcpy(&v, in.data() + pos, sizeof v);
    pos += sizeof v;
    return v;
  }
  template <class T>
  std::vector<T> get_array() {
    const auto n = get<std::uint64_t>();
    if (n > (in.size() - pos) / sizeof(T)) fail("truncated");
    std::vector<T> v(n);
    if (n > 0) std::memcpy(v.data(), in.data() + pos, n * sizeof(T));
    pos += n * sizeof(T);
    return v;
  }
};

}  // namespace voussoir
