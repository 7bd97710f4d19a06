#pragma once
#include <stdexcept>
#include <string>

namespace bedforge {

// A scene value, a command-line option or an input file that cannot be used. The message names
// the field, the value and what is allowed; the program exits with status 2.
struct InputError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// A stage that ran but could not reach its tolerances (divergence, iteration cap). The message
// says what was reached and which setting to change; the program exits with status 3.
struct ConvergenceError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// The run wrote its OpenFOAM case but could not solve it, as OpenFOAM's programs are not
// installed: everything before the case is written and kept; the program exits with status 4.
struct NotSolvedError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

}  // namespace bedforge
