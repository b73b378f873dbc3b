// cli/main.cpp - the `collide` command-line tool: the dispatch to its
// subcommands (commands.hpp), whose shared options live in options.hpp.
//
// Usage: collide <command> [options]; commands are `solve`, `gen`, `convert` and
// `report`.
// Every error is one line on stderr starting with "collide: ", and the exit
// code says which kind (see options.hpp).
#include <cstdio>
#include <exception>
#include <new>
#include <string_view>

#include "commands.hpp"
#include "options.hpp"

namespace collide::cli {

namespace {

const char* const kMainUsage =
    "usage: collide <command> [options]\n"
    "\n"
    "Batched rigid-body collision impulses (see docs/collision-law.md).\n"
    "\n"
    "commands:\n"
    "  solve   resolve the contacts of a scene: read its bodies and contacts files,\n"
    "          write the bodies with their new velocities and the impulses\n"
    "  gen     write a random scene (pairs, debris, pile or chain) as bodies and\n"
    "          contacts files\n"
    "  convert convert a bodies, contacts or impulses file between CSV and the\n"
    "          binary format (.npz)\n"
    "  report  measure every variant's speed and error on millions of random\n"
    "          collisions: a table, and optionally JSON and a PNG plot\n"
    "\n"
    "Run 'collide <command> --help' for the options of a command.\n"
    "\n"
    "exit codes: 0 success, 1 bad input or I/O error (nothing written),\n"
    "            2 usage error, 3 solve --check (or report) found an error above the bound\n";

}  // namespace
}  // namespace collide::cli

int main(int argc, char** argv) {
  using namespace collide::cli;
  if (argc < 2) {
    std::fputs(kMainUsage, stderr);
    return kExitUsage;
  }
  const std::string_view command = argv[1];
  if (command == "--help" || command == "-h" || command == "help") {
    std::fputs(kMainUsage, stdout);
    return kExitOk;
  }
  if (command == "--version") {
    std::puts("collide 0.1.0");
    return kExitOk;
  }
  try {
    if (command == "solve") return run_solve(argc, argv);
    if (command == "gen") return run_gen(argc, argv);
    if (command == "report") return run_report(argc, argv);
    if (command == "convert") return run_convert(argc, argv);
    std::fprintf(stderr,
                 "collide: unknown command '%s' (the commands: solve, gen, convert, report)\nsee 'collide --help'\n",
                 argv[1]);
    return kExitUsage;
  } catch (const UsageError& e) {
    // The one line that says what is wrong, and where the options are.
    std::fprintf(stderr, "collide %s: %s\nsee 'collide %s --help'\n", argv[1], e.what(), argv[1]);
    return kExitUsage;
  } catch (const std::bad_alloc&) {
    std::fputs("collide: out of memory\n", stderr);
    return kExitBadInput;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "collide: %s\n", e.what());
    return kExitBadInput;
  }
}
