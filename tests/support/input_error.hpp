#pragma once
// Tests of bad input: what the InputError says.
#include <string>

#include "core/error.hpp"

namespace input_error_test {

// The message of the InputError thrown by f, or "" when none is thrown.
template <class F>
std::string error_of(F f) {
  try {
    f();
  } catch (const bedforge::InputError& e) {
    return e.what();
  }
  return "";
}

}  // namespace input_error_test
