#pragma once

namespace bedforge {

// The `bedforge` command line: subcommands run, pack, import, analyse. Returns the exit status;
// lets InputError and ConvergenceError through for main to report.
int run_command_line(int argc, char** argv);

}  // namespace bedforge
