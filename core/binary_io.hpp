#pragma once
#include <cstdint>
#include <istream>
#include <ostream>
#include <string>
#include <vector>

namespace bedforge {

// Vectors of plain values and strings in bedforge's own binary scratch files (plane layers,
// processor faces), written and read by the same build on the same machine: a 64-bit count, then
// the values as they lie in memory.
template <class T>
void put_vector(std::ostream& out, const std::vector<T>& v) {
  const std::uint64_t n = v.size();
  out.write(reinterpret_cast<const char*>(&n), sizeof n);
  out.write(reinterpret_cast<const char*>(v.data()), static_cast<std::streamsize>(n * sizeof(T)));
}
inline void put_string(std::ostream& out, const std::string& s) {
  put_vector(out, std::vector<char>(s.begin(), s.end()));
}

// Reads back what put_vector wrote; false when the file ends first or its count cannot be one.
template <class T>
bool get_vector(std::istream& in, std::vector<T>& v) {
  std::uint64_t n = 0;
  if (!in.read(reinterpret_cast<char*>(&n), sizeof n) || n > (std::uint64_t{1} << 40) / sizeof(T)) return false;
  v.resize(n);
  return static_cast<bool>(in.read(reinterpret_cast<char*>(v.data()), static_cast<std::streamsize>(n * sizeof(T))));
}
inline bool get_string(std::istream& in, std::string& s) {
  std::vector<char> c;
  if (!get_vector(in, c)) return false;
  s.assign(c.begin(), c.end());
  return true;
}

}  // namespace bedforge
