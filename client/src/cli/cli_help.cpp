#include "cli_help.h"

#include <algorithm>
#include <numeric>

#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "exit_codes.h"

namespace inscribe::cli {

int EditDistance(absl::string_view a, absl::string_view b) {
  const std::size_t n = a.size(), m = b.size();
  // Three rows of the dynamic programme: two back (for swaps), one back, this one.
  std::vector<int> two_back(m + 1), back(m + 1), row(m + 1);
  std::iota(back.begin(), back.end(), 0);
  for (std::size_t i = 1; i <= n; ++i) {
    row[0] = static_cast<int>(i);
    for (std::size_t j = 1; j <= m; ++j) {
      const int substitution = back[j - 1] + (a[i - 1] == b[j - 1] ? 0 : 1);
      row[j] = std::min({back[j] + 1, row[j - 1] + 1, substitution});
      if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1]) {
        row[j] = std::min(row[j], two_back[j - 2] + 1);
      }
    }
    std::swap(two_back, back);
    std::swap(back, row);
  }
  return back[m];
}

std::vector<std::string> NearNames(absl::string_view typed,
                                   const std::vector<std::string>& candidates) {
  const int limit = std::max<int>(1, static_cast<int>(typed.size()) / 3);
  std::vector<std::pair<int, std::size_t>> scored;  // (distance, index in candidates)
  for (std::size_t i = 0; i < candidates.size(); ++i) {
    const std::string& name = candidates[i];
    if (name == typed) continue;
    int distance = EditDistance(typed, name);
    if (typed.size() >= 3 && absl::StartsWith(name, typed)) distance = std::min(distance, limit);
    if (distance <= limit) scored.emplace_back(distance, i);
  }
  std::stable_sort(scored.begin(), scored.end(),
                   [](const auto& x, const auto& y) { return x.first < y.first; });
  std::vector<std::string> near;
  for (const auto& [distance, index] : scored) {
    if (near.size() == 3) break;
    near.push_back(candidates[index]);
  }
  return near;
}

std::string DidYouMean(const std::vector<std::string>& near) {
  if (near.empty()) return "";
  if (near.size() == 1) return absl::StrCat(" (did you mean ", near[0], "?)");
  return absl::StrCat(" (did you mean ", absl::StrJoin(near.begin(), near.end() - 1, ", "), " or ",
                      near.back(), "?)");
}

namespace {

std::vector<std::string> SubcommandNames(const CLI::App& app) {
  std::vector<std::string> names;
  for (const CLI::App* sub : app.get_subcommands([](const CLI::App*) { return true; })) {
    names.push_back(sub->get_name());
    for (const std::string& alias : sub->get_aliases()) names.push_back(alias);
  }
  return names;
}

// Every spelling of every option of `cmd`: "--name" for long names, "-n" for short ones.
std::vector<std::string> OptionSpellings(const CLI::App& cmd) {
  std::vector<std::string> spellings;
  for (const CLI::Option* option : cmd.get_options()) {
    for (const std::string& name : option->get_lnames()) spellings.push_back("--" + name);
    for (const std::string& name : option->get_snames()) spellings.push_back("-" + name);
  }
  return spellings;
}

}  // namespace

std::optional<std::string> UnknownSubcommandMessage(const CLI::App& app, int argc,
                                                    const char* const* argv) {
  if (argc < 2) return std::nullopt;
  const absl::string_view first = argv[1];
  if (first.empty() || first[0] == '-') return std::nullopt;
  const std::vector<std::string> names = SubcommandNames(app);
  if (std::find(names.begin(), names.end(), first) != names.end()) return std::nullopt;
  std::vector<std::string> listed;
  for (const CLI::App* sub : app.get_subcommands([](const CLI::App*) { return true; })) {
    listed.push_back(sub->get_name());
  }
  return absl::StrCat("unknown subcommand '", first, "'", DidYouMean(NearNames(first, names)),
                      "; the subcommands are ", absl::StrJoin(listed, ", "),
                      " (inscribe --help, inscribe SUBCOMMAND --help)");
}

std::vector<std::string> UnknownOptionMessages(const CLI::App& app) {
  // With fallthrough an option the subcommand does not know is left with the main app, so the
  // extras of both count, named after the subcommand that ran.
  const std::vector<const CLI::App*> ran =
      app.get_subcommands([](const CLI::App* sub) { return sub->parsed(); });
  std::vector<std::string> spellings = OptionSpellings(app);
  std::string command = "inscribe";
  if (!ran.empty()) {
    const std::vector<std::string> own = OptionSpellings(*ran.front());
    spellings.insert(spellings.end(), own.begin(), own.end());
    command = absl::StrCat("inscribe ", ran.front()->get_name());
  }
  std::vector<std::string> messages;
  for (const std::string& extra : app.remaining(/*recurse=*/true)) {
    if (extra.size() < 2 || extra[0] != '-') continue;
    const std::string typed = extra.substr(0, extra.find('='));
    messages.push_back(absl::StrCat(command, ": unknown option ", typed,
                                    DidYouMean(NearNames(typed, spellings)), " (", command,
                                    " --help lists its options)"));
  }
  return messages;
}

void SetExitStatusHelp(CLI::App* cmd, absl::string_view unusable) {
  std::string text = absl::StrCat("Exit status: ", kExitOk, " done");
  if (!unusable.empty()) absl::StrAppend(&text, "; ", kExitUnusableMesh, " ", unusable);
  absl::StrAppend(&text, "; ", kExitBadInput, " missing, unreadable or malformed input; ",
                  kExitUsage, " bad command line");
  if (cmd->get_option_no_throw("--server") != nullptr) {
    absl::StrAppend(&text, "; ", kExitServerUnavailable,
                    " the --server could not be reached or did not answer within --timeout; ",
                    kExitNotAuthorized,
                    " the --server refused the call (missing or wrong --token-file)");
  }
  absl::StrAppend(&text, "; ", kExitInternal, " internal error.\n");
  cmd->footer(text);
}

}  // namespace inscribe::cli
