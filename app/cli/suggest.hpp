// "Did you mean …?" for a command line CLI11 refused: the nearest verb or flag to the word it
// could not place, by edit distance.
#pragma once

#include <CLI/CLI.hpp>

#include <string>
#include <vector>

namespace spinesim::cli {

/// Levenshtein distance (insertions, deletions, substitutions; each costs 1).
int edit_distance(const std::string& a, const std::string& b);

/// The candidate nearest to `word` when it is near enough to be a typo (distance at most
/// max(2, |word| / 3)); empty otherwise.
std::string nearest(const std::string& word, const std::vector<std::string>& candidates);

/// Walks `args` (without the program name) down `app`'s sub-commands as CLI11 would and returns
/// a hint for the first word it cannot place: "unknown verb 'dsic' for 'spinesim mesh' (did you
/// mean 'disc'?)" or "unknown flag '--levl' for 'spinesim mesh disc' (did you mean
/// '--level'?)"; the verbs there are listed when none is near. Empty when every word has a place.
std::string suggest(const CLI::App& app, const std::vector<std::string>& args);

}  // namespace spinesim::cli
