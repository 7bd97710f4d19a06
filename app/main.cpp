#include <cstdio>
#include <exception>

#include "app/commands.hpp"
#include "core/error.hpp"

int main(int argc, char** argv) {
  try {
    return bedforge::run_command_line(argc, argv);
  } catch (const bedforge::InputError& e) {
    std::fprintf(stderr, "bedforge: error: %s\n", e.what());
    return 2;
  } catch (const bedforge::ConvergenceError& e) {
    std::fprintf(stderr, "bedforge: did not converge: %s\n", e.what());
    return 3;
  } catch (const bedforge::NotSolvedError& e) {
    std::fprintf(stderr, "bedforge: not solved: %s\n", e.what());
    return 4;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bedforge: internal error: %s\n", e.what());
    return 1;
  }
}
