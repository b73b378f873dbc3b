// cli/commands.hpp - the subcommands of the `collide` tool: one entry point
// and one usage text each (cmd_<command>.cpp), dispatched by main.cpp. What
// they share, the exit codes and the option parsing, is options.hpp's.
#pragma once

#include "options.hpp"

namespace collide::cli {

int run_solve(int argc, char** argv);
int run_gen(int argc, char** argv);
int run_report(int argc, char** argv);
int run_convert(int argc, char** argv);

extern const char* const kSolveUsage;
extern const char* const kGenUsage;
extern const char* const kReportUsage;
extern const char* const kConvertUsage;

}  // namespace collide::cli
