// What the command line says when it is used wrongly or asked for help: near matches for a
// mistyped subcommand or option ("did you mean"), and each subcommand's own exit statuses.
#pragma once

#include <CLI/CLI.hpp>
#include <optional>
#include <string>
#include <vector>

#include "absl/strings/string_view.h"

namespace inscribe::cli {

// The optimal-string-alignment distance: insertions, deletions, substitutions and swaps of two
// neighbours, each 1. Case-sensitive.
int EditDistance(absl::string_view a, absl::string_view b);

// The names among `candidates` closest to `typed`, within max(1, typed.size() / 3) edits (or
// holding `typed` as a prefix of at least 3 characters), best first; ties in candidates' order.
// At most three.
std::vector<std::string> NearNames(absl::string_view typed,
                                   const std::vector<std::string>& candidates);

// " (did you mean X?)" / " (did you mean X or Y?)", or "" when `near` is empty.
std::string DidYouMean(const std::vector<std::string>& near);

// Before parsing: when the first argument is not an option and names no subcommand of `app`,
// the message saying so, with near matches and the list of subcommands. nullopt otherwise.
std::optional<std::string> UnknownSubcommandMessage(const CLI::App& app, int argc,
                                                    const char* const* argv);

// After a parse failure: for each argument the subcommand that ran did not take and that looks
// like an option (starts with '-'), "inscribe CMD: unknown option --X (did you mean --Y?)".
// Empty when there are none (the failure was something else: CLI11's own message stands).
std::vector<std::string> UnknownOptionMessages(const CLI::App& app);

// Sets `cmd`'s help footer to the exit statuses it can end with: 0, 1 when `unusable` is not
// empty (its meaning), 2, 64, 70, and 69 and 77 only when `cmd` has a --server option. Call
// after every option is added.
void SetExitStatusHelp(CLI::App* cmd, absl::string_view unusable);

}  // namespace inscribe::cli
