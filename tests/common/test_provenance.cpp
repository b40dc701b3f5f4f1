// The provenance record: SHA-256 against the standard's test vectors and coreutils, the shell
// quoting that makes the recorded command re-runnable (checked by a real shell), input paths
// relative to the working folder, and nothing at all outside a recorded run.
#include "spinesim/common/input_file.hpp"
#include "spinesim/common/provenance.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

namespace {

namespace fs = std::filesystem;

fs::path scratch(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("spinesim-provenance-" + std::to_string(::getpid()));
  fs::create_directories(d);
  return d / name;
}

void write(const fs::path& p, const std::string& text) {
  std::ofstream(p, std::ios::binary) << text;
}

std::string command_output(const std::string& cmd) {
  std::string out;
  if (FILE* f = ::popen(cmd.c_str(), "r")) {
    char buf[256];
    while (std::fgets(buf, sizeof buf, f)) out += buf;
    ::pclose(f);
  }
  return out;
}

// FIPS 180-2's examples, an empty file, and a file larger than the read buffer against sha256sum.
TEST(Provenance, Sha256MatchesTheStandardAndCoreutils) {
  write(scratch("abc"), "abc");
  EXPECT_EQ(spinesim::sha256_of_file(scratch("abc").string()),
            "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  write(scratch("empty"), "");
  EXPECT_EQ(spinesim::sha256_of_file(scratch("empty").string()),
            "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
  std::string big;
  for (int i = 0; i < 300000; ++i) big += char('a' + i % 26);
  write(scratch("big"), big);
  const std::string coreutils = command_output("sha256sum '" + scratch("big").string() + "'");
  EXPECT_EQ(spinesim::sha256_of_file(scratch("big").string()), coreutils.substr(0, 64));
  EXPECT_EQ(spinesim::sha256_of_file(scratch("no-such-file").string()), "");
}

// What the shell reads back from each quoted word is the word.
TEST(Provenance, ShellQuotingRoundTripsThroughAShell) {
  for (const std::string word : {"plain-word_1.vtu", "a b", "it's", "$HOME", "x;rm -rf y", "",
                                 "tab\there", "back\\slash", "\"quoted\""}) {
    const std::string echoed = command_output("printf '%s' " + spinesim::shell_quoted(word));
    EXPECT_EQ(echoed, word) << spinesim::shell_quoted(word);
  }
  EXPECT_EQ(spinesim::shell_quoted("--mesh"), "--mesh");  // plain words stay plain
}

// Outside a recorded run nothing is added; inside, the command, the folder and each input once,
// its path relative to the folder, its hash following the file's content.
TEST(Provenance, RecordsTheCommandAndEachInputOnce) {
  EXPECT_TRUE(spinesim::run_provenance().is_null());
  EXPECT_EQ(spinesim::csv_provenance_line(), "");
  EXPECT_EQ(spinesim::with_provenance({{"a", 1}}), nlohmann::json({{"a", 1}}));

  const fs::path input = scratch("in.json");
  write(input, "{\"x\": 1}");
  const fs::path before = fs::current_path();
  fs::current_path(input.parent_path());
  const char* argv[] = {"spinesim", "fem", "--mesh", "a b.vtu"};
  spinesim::record_run_command(4, argv);
  (void)spinesim::read_json_file("in.json", "test file");
  (void)spinesim::read_json_file(input.string(), "test file");  // the same file: once
  spinesim::record_input_file("no-such-file.json");             // never read: not recorded
  fs::current_path(before);

  nlohmann::json p = spinesim::run_provenance();
  EXPECT_EQ(p["program"], "spinesim");
  EXPECT_EQ(p["version"], spinesim::build_version());
  EXPECT_EQ(p["commit"], spinesim::build_commit());
  EXPECT_EQ(p["command"], "spinesim fem --mesh 'a b.vtu'");
  EXPECT_EQ(p["working_directory"], input.parent_path().string());
  // This file once (other tests in the same process may have read files before it).
  const auto entry = [&](const nlohmann::json& q) {
    nlohmann::json found = nullptr;
    int count = 0;
    for (const auto& in : q["inputs"]) {
      EXPECT_NE(in["path"], "no-such-file.json");
      if (in["path"] == "in.json") found = in, ++count;
    }
    EXPECT_EQ(count, 1);
    return found;
  };
  ASSERT_FALSE(entry(p).is_null());
  EXPECT_EQ(entry(p)["bytes"], 8);
  EXPECT_EQ(entry(p)["sha256"], spinesim::sha256_of_file(input.string()));

  write(input, "{\"x\": 22}");  // changed after it was read: the record says what is there now
  fs::last_write_time(input, fs::last_write_time(input) + std::chrono::seconds(2));
  p = spinesim::run_provenance();
  EXPECT_EQ(entry(p)["bytes"], 9);
  EXPECT_EQ(entry(p)["sha256"], spinesim::sha256_of_file(input.string()));

  const std::string line = spinesim::csv_provenance_line();
  ASSERT_EQ(line.rfind("# provenance: ", 0), 0u);
  EXPECT_EQ(line.back(), '\n');
  EXPECT_EQ(line.find('\n'), line.size() - 1);  // one line
  EXPECT_EQ(nlohmann::json::parse(line.substr(14)), p);
  EXPECT_EQ(spinesim::with_provenance({{"a", 1}})["provenance"], p);
  EXPECT_EQ(spinesim::with_provenance(nlohmann::json::array({1})), nlohmann::json::array({1}));
  fs::remove_all(input.parent_path());
}

}  // namespace
