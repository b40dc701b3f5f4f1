// Safe input and output paths: only regular files are read or replaced, JSON is bounded in
// depth and parsed strictly, and every refusal names the file and the cause.
#include "spinesim/common/atomic_file.hpp"
#include "spinesim/common/input_file.hpp"

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <random>
#include <string>

namespace fs = std::filesystem;

namespace {

std::string tmp(const std::string& name) {
  const fs::path dir = fs::path(SPINESIM_TEST_TMP) / ("common-" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const fs::path p = dir / name;
  fs::remove_all(p);
  return p.string();
}

void write(const std::string& path, const std::string& text) { std::ofstream(path) << text; }

/// The refusal's message, or "" when nothing was thrown.
template <class F>
std::string refusal(F&& f) {
  try {
    f();
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

}  // namespace

// The depth scan against the nesting it was built with, brackets inside strings ignored.
TEST(JsonDepth, MatchesTheNestingOfRandomDocuments) {
  std::mt19937 rng(7);
  for (int trial = 0; trial < 200; ++trial) {
    const int depth = int(rng() % 40);
    std::string text, close;
    for (int d = 0; d < depth; ++d) {
      const bool object = rng() % 2;
      text += object ? "{\"k[{\\\"\": " : "[\"]}\", ";
      close = (object ? "}" : "]") + close;
    }
    text += "1" + close;
    ASSERT_EQ(spinesim::json_depth(text), depth) << text;
    nlohmann::json parsed;
    EXPECT_NO_THROW(parsed = nlohmann::json::parse(text)) << text;  // the documents are valid
  }
}

TEST(ReadJsonFile, RefusesTooDeepTrailingGarbageAndNonFilesNamingThem) {
  const std::string deep = tmp("deep.json");
  write(deep, std::string(100000, '[') + std::string(100000, ']'));
  std::string e = refusal([&] { spinesim::read_json_file(deep, "tuned-disc file"); });
  EXPECT_NE(e.find("nested 100000 levels"), std::string::npos) << e;
  EXPECT_NE(e.find(deep), std::string::npos) << e;

  const std::string trailing = tmp("trailing.json");
  write(trailing, "{\"a\": 1} garbage");
  e = refusal([&] { spinesim::read_json_file(trailing, "material file"); });
  EXPECT_NE(e.find("not valid JSON"), std::string::npos) << e;

  e = refusal([&] { spinesim::read_json_file(tmp("missing.json"), "material file"); });
  EXPECT_NE(e.find("no such file"), std::string::npos) << e;

  const std::string dir = tmp("a-folder");
  fs::create_directories(dir);
  e = refusal([&] { spinesim::read_json_file(dir, "material file"); });
  EXPECT_NE(e.find("a directory, not a regular file"), std::string::npos) << e;

  // A FIFO with no writer: refused at once, never waited on.
  const std::string fifo = tmp("fifo");
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  e = refusal([&] { spinesim::read_json_file(fifo, "material file"); });
  EXPECT_NE(e.find("a FIFO, not a regular file"), std::string::npos) << e;

  // Found by fuzzing: a number beyond double's range made the parser throw its own exception
  // type, which nothing caught; now a refusal naming the file.
  const std::string huge = tmp("huge-number.json");
  write(huge, "{\"E_mpa\": 0.2250555265182e461}");
  e = refusal([&] { spinesim::read_json_file(huge, "material file"); });
  EXPECT_NE(e.find(huge), std::string::npos) << e;
  EXPECT_NE(e.find("number overflow"), std::string::npos) << e;
  EXPECT_EQ(e.find("[json.exception"), std::string::npos) << e;

  const std::string good = tmp("good.json");
  write(good, "{\"a\": [1, 2, {\"b\": \"[[[\"}]}\n");
  EXPECT_EQ(spinesim::read_json_file(good, "file")["a"][2]["b"], "[[[");
  spinesim::InputLimits small;
  small.max_bytes = 4;
  e = refusal([&] { spinesim::read_regular_file(good, "file", small); });
  EXPECT_NE(e.find("more than the limit of 4"), std::string::npos) << e;
}

// The writer replaces regular files only: not a device, a FIFO, a link or a folder.
TEST(AtomicWrite, NeverReplacesWhatIsNotARegularFile) {
  const std::string target = tmp("target.txt"), link = tmp("link.txt"), fifo = tmp("out-fifo");
  write(target, "original");
  fs::create_symlink(target, link);
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  for (const std::string& path :
       {link, fifo, std::string("/dev/null"), fs::path(target).parent_path().string()}) {
    SCOPED_TRACE(path);
    const std::string e = refusal([&] { spinesim::write_text_atomically(path, "new"); });
    EXPECT_NE(e.find("not a regular file: refusing to replace it"), std::string::npos) << e;
  }
  EXPECT_TRUE(fs::is_symlink(link));
  EXPECT_EQ(fs::status(fifo).type(), fs::file_type::fifo);
  EXPECT_EQ(fs::status("/dev/null").type(), fs::file_type::character);
  std::ifstream in(target);
  std::string text;
  std::getline(in, text);
  EXPECT_EQ(text, "original");
  // A regular file is replaced, and no temporary file is left beside it.
  spinesim::write_text_atomically(target, "new");
  std::ifstream again(target);
  std::getline(again, text);
  EXPECT_EQ(text, "new");
  for (const auto& entry : fs::directory_iterator(fs::path(target).parent_path()))
    EXPECT_EQ(entry.path().string().find(".tmp-"), std::string::npos) << entry.path();
}

// Files that belong together appear together: a set abandoned before commit() leaves nothing.
TEST(OutputSet, AllOrNothing) {
  const std::string a = tmp("set-a.vtu"), b = tmp("set-b.mesh");
  {
    spinesim::OutputSet set("test");
    write(set.stage(a), "a");
    write(set.stage(b), "b");
    // destroyed without commit, as when the second write throws
  }
  EXPECT_FALSE(fs::exists(a));
  EXPECT_FALSE(fs::exists(b));
  for (const auto& e : fs::directory_iterator(fs::path(a).parent_path()))
    EXPECT_EQ(e.path().string().find(".staged-"), std::string::npos) << e.path();
  spinesim::OutputSet set("test");
  write(set.stage(a), "a");
  write(set.stage(b), "b");
  set.commit();
  EXPECT_TRUE(fs::exists(a));
  EXPECT_TRUE(fs::exists(b));
  EXPECT_THROW(set.stage("/dev/null"), std::invalid_argument);
}

TEST(ResolvePreset, ThePathItselfThenTheFolderThenOneLineListingThePresets) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::path(SPINESIM_TEST_TMP) / "presets";
  fs::create_directories(dir);
  for (const char* n : {"zeta", "alpha"}) std::ofstream(dir / (std::string(n) + ".json")) << "{}";
  std::ofstream(dir / "notes.txt") << "not a preset";
  EXPECT_EQ(spinesim::resolve_preset("alpha", dir.string(), "thing"),
            (dir / "alpha.json").string());
  const std::string direct = (dir / "zeta.json").string();
  EXPECT_EQ(spinesim::resolve_preset(direct, "/nonexistent", "thing"), direct);
  try {
    spinesim::resolve_preset("beta", dir.string(), "thing");
    ADD_FAILURE() << "expected a refusal";
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(), "unknown thing 'beta' (no such file; presets: alpha, zeta)");
  }
}
