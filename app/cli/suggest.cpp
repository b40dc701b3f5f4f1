#include "suggest.hpp"

#include <algorithm>
#include <numeric>

namespace spinesim::cli {

int edit_distance(const std::string& a, const std::string& b) {
  std::vector<int> row(b.size() + 1);
  std::iota(row.begin(), row.end(), 0);
  for (std::size_t i = 1; i <= a.size(); ++i) {
    int diagonal = row[0];
    row[0] = int(i);
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const int up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diagonal = up;
    }
  }
  return row[b.size()];
}

std::string nearest(const std::string& word, const std::vector<std::string>& candidates) {
  std::string best;
  int best_distance = std::max(2, int(word.size()) / 3) + 1;
  for (const std::string& c : candidates) {
    const int d = edit_distance(word, c);
    if (d < best_distance) best = c, best_distance = d;
  }
  return best;
}

namespace {

/// The verbs under `cmd`; hidden ones (an empty group) only when `hidden`.
std::vector<std::string> verbs_of(const CLI::App& cmd, bool hidden) {
  std::vector<std::string> out;
  for (const CLI::App* sub : cmd.get_subcommands([](const CLI::App*) { return true; }))
    if (hidden || !sub->get_group().empty()) out.push_back(sub->get_name());
  return out;
}

std::vector<std::string> flags_of(const CLI::App& cmd) {
  std::vector<std::string> out;
  for (const CLI::App* c = &cmd; c; c = c->get_parent())
    for (const CLI::Option* o : c->get_options()) {
      for (const auto& l : o->get_lnames()) out.push_back("--" + l);
      for (const auto& s : o->get_snames()) out.push_back("-" + s);
    }
  return out;
}

const CLI::Option* find_flag(const CLI::App& cmd, const std::string& name) {
  for (const CLI::App* c = &cmd; c; c = c->get_parent())
    for (const CLI::Option* o : c->get_options())
      if (o->check_name(name)) return o;
  return nullptr;
}

std::string path_of(const CLI::App& cmd) {
  std::string p;
  for (const CLI::App* c = &cmd; c; c = c->get_parent())
    p = c->get_parent() ? c->get_name() + (p.empty() ? "" : " " + p) : p;
  return "spinesim" + (p.empty() ? "" : " " + p);
}

std::string join(const std::vector<std::string>& v) {
  std::string out;
  for (const auto& s : v) out += (out.empty() ? "" : ", ") + s;
  return out;
}

}  // namespace

std::string suggest(const CLI::App& app, const std::vector<std::string>& args) {
  const CLI::App* cmd = &app;
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& word = args[i];
    if (word == "--") return "";
    if (word.size() > 1 && word[0] == '-') {
      const std::string name = word.substr(0, word.find('='));
      const CLI::Option* opt = find_flag(*cmd, name);
      if (!opt) {
        const std::string near = nearest(name, flags_of(*cmd));
        return "unknown flag '" + name + "' for '" + path_of(*cmd) + "'" +
               (near.empty() ? "" : " (did you mean '" + near + "'?)");
      }
      // A flag's values follow it (unless given as --flag=value).
      if (word.find('=') == std::string::npos)
        for (int k = 0; k < opt->get_items_expected_min() && i + 1 < args.size(); ++k) ++i;
      continue;
    }
    const std::vector<std::string> all = verbs_of(*cmd, true);
    if (std::find(all.begin(), all.end(), word) != all.end()) {
      cmd = cmd->get_subcommand(word);
      continue;
    }
    if (all.empty()) continue;  // a positional value of a leaf verb
    const std::vector<std::string> verbs = verbs_of(*cmd, false);
    const std::string near = nearest(word, verbs);
    return "unknown verb '" + word + "' for '" + path_of(*cmd) + "' (" +
           (near.empty() ? "the verbs are " + join(verbs) : "did you mean '" + near + "'?") + ")";
  }
  return "";
}

}  // namespace spinesim::cli
