// core/ is the algorithm and nothing else, on Eigen alone (docs/architecture.md): file formats,
// OctoMap, YAML and DDS live beside it. This reads every source of core/ and its CMakeLists.txt
// and fails on any other dependency, so that the rule cannot erode one include at a time.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace {

namespace fs = std::filesystem;

std::string read_text(const fs::path& path) {
  std::ifstream in(path);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

// The target of an #include line and whether it is in <angle brackets>; nullopt for any other
// line. (Parsed by hand: GCC 12's -Wmaybe-uninitialized misfires inside libstdc++'s <regex> at
// the sanitizer stage's -O1, and warnings are errors.)
std::optional<std::pair<std::string, bool>> include_of(const std::string& line) {
  size_t i = line.find_first_not_of(" \t");
  if (i == std::string::npos || line[i] != '#') return std::nullopt;
  i = line.find_first_not_of(" \t", i + 1);
  if (i == std::string::npos || line.compare(i, 7, "include") != 0) return std::nullopt;
  i = line.find_first_not_of(" \t", i + 7);
  if (i == std::string::npos || (line[i] != '<' && line[i] != '"')) return std::nullopt;
  const bool angle = line[i] == '<';
  const size_t end = line.find(angle ? '>' : '"', i + 1);
  if (end == std::string::npos) return std::nullopt;
  return std::make_pair(line.substr(i + 1, end - i - 1), angle);
}

// The standard library (no file extension), Eigen, and core's own headers; and in the one file
// that reserves the searches' memory, the system's calls for anonymous mappings (POSIX, part of
// the system, not a library to install; it falls back to std::calloc without them): the only
// way to reserve an array that is committed where it is written and to hand its pages back.
bool allowed_include(const std::string& file, const std::string& target, bool angle) {
  if (file == "src/lazy_array.hpp" && angle && (target == "sys/mman.h" || target == "unistd.h"))
    return true;
  if (angle) return target.rfind("Eigen/", 0) == 0 || target.find('.') == std::string::npos;
  return target.rfind("vnsba/core/", 0) == 0 || target.find('/') == std::string::npos;
}

TEST(CoreDependencies, CoreIncludesOnlyTheStandardLibraryEigenAndItself) {
  const fs::path core = fs::path(VNSBA_SOURCE_DIR) / "core";
  ASSERT_TRUE(fs::is_directory(core)) << core;
  size_t files = 0;
  std::vector<std::string> offences;
  for (const auto& entry : fs::recursive_directory_iterator(core)) {
    const std::string ext = entry.path().extension().string();
    if (ext != ".cpp" && ext != ".hpp") continue;
    ++files;
    const std::string file = entry.path().lexically_relative(core).generic_string();
    std::istringstream lines(read_text(entry.path()));
    std::string line;
    while (std::getline(lines, line)) {
      const auto include = include_of(line);
      if (include && !allowed_include(file, include->first, include->second)) {
        offences.push_back(file + ": " + line);
      }
    }
  }
  EXPECT_GT(files, 10u) << "core/ sources not found under " << core;
  EXPECT_TRUE(offences.empty()) << "core/ includes beyond the standard library and Eigen:\n"
                                << ::testing::PrintToString(offences);
}

TEST(CoreDependencies, CoreLinksOnlyEigen) {
  const std::string cmake = read_text(fs::path(VNSBA_SOURCE_DIR) / "core" / "CMakeLists.txt");
  ASSERT_FALSE(cmake.empty());
  const std::string call = "target_link_libraries(${name}";
  const size_t begin = cmake.find(call);
  ASSERT_NE(begin, std::string::npos) << "core's target_link_libraries not found";
  const size_t end = cmake.find(')', begin + call.size());
  ASSERT_NE(end, std::string::npos);
  std::istringstream words(cmake.substr(begin + call.size(), end - begin - call.size()));
  std::string word;
  while (words >> word) {
    EXPECT_TRUE(word == "PUBLIC" || word == "PRIVATE" || word == "Eigen3::Eigen" ||
                word == "vnsba_warnings")
        << "core/ links " << word;
  }
}

}  // namespace
