// The glint command line (DESIGN.md §6): turns arguments into library calls and results into
// messages and an exit status. All rendering logic lives in the library.
#pragma once

namespace glint::cli {

// Exit statuses of the glint command (DESIGN.md §6, §7). An interrupted run exits with
// 128 + the signal number (130 for SIGINT, 143 for SIGTERM, 129 for SIGHUP).
inline constexpr int kExitSuccess = 0;
inline constexpr int kExitFailure = 1;  // failure while rendering or writing
inline constexpr int kExitBadInput =
    2;  // bad arguments, a bad scene, a request refused as too large

// Runs `glint render|check ...` or `glint --help|--version`. Never throws: every error becomes a
// message on stderr and an exit status.
int run(int argc, char** argv);

}  // namespace glint::cli
