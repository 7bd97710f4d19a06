#pragma once
#include <algorithm>
#include <cstdint>

namespace bedforge {

// The edge between vertices a and b (indices >= 0) as one number, the same for (a, b) and
// (b, a): a key for the hash maps that pair triangles or faces across their shared edges.
inline std::uint64_t edge_key(int a, int b) {
  return (static_cast<std::uint64_t>(std::min(a, b)) << 32) | static_cast<std::uint32_t>(std::max(a, b));
}

}  // namespace bedforge
