// Issue 45: no test may read a path it did not make. A test that wrote into a fixed folder of the
// shared temp directory passed only where an earlier run had left the file it needed. Every
// scratch path now comes from FreshTempDir (tests/temp_dir.hpp); this test scans the test sources
// (tests/**/*.cpp, .hpp, .c, .h) and fails, naming file and line, for any other way of naming the
// system's temp directory, of making a temp file, or for a fixed absolute path a test assumes
// absent. The helper itself is the one file allowed to.
//
// The forbidden spellings are assembled at run time ("Temp" + "Dir()"), never written whole in
// this file, so that it is scanned like every other file and has nothing to hide.
#include <gtest/gtest.h>

#include <cctype>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

namespace vnsba::test {
namespace {

namespace fs = std::filesystem;

// The one file that may name the temp directory: the helper that makes fresh folders in it.
const std::string kHelper = "tests/temp_dir.hpp";

struct Rule {
  enum Kind {
    kText,  // anywhere
    kPath,  // an absolute path: not preceded by a name or '.' (build/tmp, ./tmp are no match)
    kCall,  // a function called: a whole name followed by '('
  };
  std::string needle;
  Kind kind;
  std::string why;
};

const std::vector<Rule>& rules() {
  static const std::vector<Rule> all = {
      {std::string("Temp") + "Dir()", Rule::kText,
       "gtest's temp folder is shared by every test and every run: use FreshTempDir"},
      {std::string("temp_directory") + "_path", Rule::kText,
       "the system's temp folder is shared by every test and every run: use FreshTempDir"},
      {std::string("/t") + "mp", Rule::kPath,
       "a fixed path in the shared temp folder: use FreshTempDir"},
      {std::string("/non") + "existent", Rule::kPath,
       "a fixed path assumed absent: use a name inside a FreshTempDir"},
      {std::string("/no/") + "such", Rule::kPath,
       "a fixed path assumed absent: use a name inside a FreshTempDir"},
      {std::string("\"TMP") + "DIR\"", Rule::kText,
       "reads or sets the temp folder itself: use FreshTempDir"},
      {std::string("\"TEST_TMP") + "DIR\"", Rule::kText,
       "reads or sets gtest's temp folder itself: use FreshTempDir"},
      {std::string("mkd") + "temp", Rule::kCall, "makes its own temp folder: use FreshTempDir"},
      {std::string("mks") + "temp", Rule::kCall, "makes its own temp file: use FreshTempDir"},
      {std::string("tmp") + "nam", Rule::kCall, "names its own temp file: use FreshTempDir"},
      {std::string("tmp") + "file", Rule::kCall, "makes its own temp file: use FreshTempDir"},
  };
  return all;
}

bool name_char(char c) {
  return std::isalnum(static_cast<unsigned char>(c)) || c == '_';
}

bool matches_at(const std::string& line, size_t at, const Rule& rule) {
  const size_t end = at + rule.needle.size();
  switch (rule.kind) {
    case Rule::kText:
      return true;
    case Rule::kPath: {
      if (at > 0) {
        const char before = line[at - 1];
        if (name_char(before) || before == '.') return false;
      }
      // The whole name, not a longer one that starts the same ('-' ends a name here).
      return end == line.size() || !name_char(line[end]);
    }
    case Rule::kCall: {
      if (at > 0 && name_char(line[at - 1])) return false;
      size_t after = end;
      while (after < line.size() && line[after] == ' ') ++after;
      return after < line.size() && line[after] == '(';
    }
  }
  return false;
}

struct Finding {
  int line;  // from 1
  std::string why;
  std::string text;
};

// Every line of `text` that names a temp path of its own, with the rule it breaks.
std::vector<Finding> scan(const std::string& text) {
  std::vector<Finding> found;
  int number = 0;
  size_t begin = 0;
  while (begin <= text.size()) {
    const size_t newline = text.find('\n', begin);
    const size_t end = newline == std::string::npos ? text.size() : newline;
    const std::string line = text.substr(begin, end - begin);
    ++number;
    for (const Rule& rule : rules()) {
      bool hit = false;
      for (size_t at = line.find(rule.needle); at != std::string::npos && !hit;
           at = line.find(rule.needle, at + 1))
        hit = matches_at(line, at, rule);
      if (hit) found.push_back({number, rule.why, line});
    }
    if (newline == std::string::npos) break;
    begin = newline + 1;
  }
  return found;
}

std::string read_file(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// The scanner on planted lines: each spelling is found, on its line, and nothing else is.
TEST(TempPathScan, FindsEachForbiddenSpellingOnItsLine) {
  const std::vector<std::string> planted = {
      "  const std::string dir = ::testing::Temp" + std::string("Dir()") + " + \"/x\";",
      "  const auto dir = fs::temp_directory" + std::string("_path()") + " / \"x\";",
      "  std::ofstream(\"/t" + std::string("mp/vnsba_leftover.yaml\")") + " << text;",
      "  const std::string p = \"/t" + std::string("mp\";"),
      "  run(\"--svg\", \"/non" + std::string("existent-dir/x.svg\");"),
      "  <value>file:///no/" + std::string("such/governance.p7s</value>"),
      "  const char* base = std::getenv(\"TMP" + std::string("DIR\");"),
      "  setenv(\"TEST_TMP" + std::string("DIR\", dir, 1);"),
      "  char name[] = \"xXXXXXX\"; ::mkd" + std::string("temp(name);"),
      "  const int fd = mks" + std::string("temp (name);"),
      "  std::tmp" + std::string("nam(buffer);"),
      "  FILE* f = std::tmp" + std::string("file();"),
  };
  ASSERT_EQ(planted.size(), rules().size() + 1)
      << "one planted line per rule, two for the temp folder's path";
  for (const std::string& line : planted) {
    SCOPED_TRACE(line);
    const auto found = scan("// a test\n#include <string>\n" + line + "\nint x = 0;\n");
    ASSERT_EQ(found.size(), 1u);
    EXPECT_EQ(found[0].line, 3);
    EXPECT_EQ(found[0].text, line);
    EXPECT_FALSE(found[0].why.empty());
  }
  // Two on one line are both reported; a line number counts every line before it.
  const std::string both = "x = ::testing::Temp" + std::string("Dir() + \"/t") + "mp\";";
  const auto found = scan(std::string(40, '\n') + both);
  ASSERT_EQ(found.size(), 2u);
  EXPECT_EQ(found[0].line, 41);
  EXPECT_EQ(found[1].line, 41);
}

TEST(TempPathScan, LeavesTheHelpersCallersAndNearMissesAlone) {
  const std::vector<std::string> clean = {
      "#include \"temp_dir.hpp\"",
      "const fs::path dir = FreshTempDir(\"keystore\") / \"keystore\";",
      "const std::string out = (dir / \"tmp\" / \"x.pgm\").string();",
      "const std::string rel = \"build/t" + std::string("mp/out.svg\";"),
      "const std::string fs_name = \"/t" + std::string("mpfs\";"),
      "const std::string relative = \"./t" + std::string("mp/x\";"),
      "const std::string missing = (dir / \"no/" + std::string("such/file.yaml\").string();"),
      "// TMP" + std::string("DIR is set by tools/test.sh, unquoted here"),
      "my_tmp" + std::string("file_name(x);"),
      "int nontmp" + std::string("nam = 3;"),
      "const std::string missing = (dir / \"no_such_dir\" / \"none.yaml\").string();",
  };
  std::string text;
  for (const std::string& line : clean) text += line + "\n";
  for (const Finding& f : scan(text)) ADD_FAILURE() << f.line << ": " << f.why << "\n  " << f.text;
}

// The tree itself: every test source but the helper is clean, and the helper is not (it makes
// its folders in gtest's temp folder): a scan that found nothing there would be reading nothing.
TEST(TestTree, NoTestNamesATempPathOfItsOwn) {
  const fs::path source = VNSBA_SOURCE_DIR;
  int scanned = 0;
  std::vector<Finding> in_helper;
  for (const auto& entry : fs::recursive_directory_iterator(source / "tests")) {
    const std::string ext = entry.path().extension().string();
    if (!entry.is_regular_file() || (ext != ".cpp" && ext != ".hpp" && ext != ".c" && ext != ".h"))
      continue;
    const std::string name = entry.path().lexically_relative(source).generic_string();
    const auto found = scan(read_file(entry.path()));
    ++scanned;
    if (name == kHelper) {
      in_helper = found;
      continue;
    }
    for (const Finding& f : found)
      ADD_FAILURE() << name << ":" << f.line << ": " << f.why << " (tests/temp_dir.hpp)\n  "
                    << f.text;
  }
  // 67 files when this was written: far fewer means the walk missed the tree.
  EXPECT_GE(scanned, 50) << "test sources under " << (source / "tests").string();
  EXPECT_FALSE(in_helper.empty()) << kHelper << " (missing, or the scanner stopped seeing it)";
}

}  // namespace
}  // namespace vnsba::test
