// core/ is the algorithm and nothing else, on Eigen alone (ARCHITECTURE.md): file formats,
// OctoMap, YAML and DDS live beside it. This reads every source of core/ and its CMakeLists.txt
// and fails on any other dependency, so that the rule cannot erode one include at a time.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;

std::string read_text(const fs::path& path) {
  std::ifstream in(path);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

// The standard library (no file extension), Eigen, and core's own headers.
bool allowed_include(const std::string& target, bool angle) {
  if (angle) return target.rfind("Eigen/", 0) == 0 || target.find('.') == std::string::npos;
  return target.rfind("vnsba/core/", 0) == 0 || target.find('/') == std::string::npos;
}

TEST(CoreDependencies, CoreIncludesOnlyTheStandardLibraryEigenAndItself) {
  const fs::path core = fs::path(VNSBA_SOURCE_DIR) / "core";
  ASSERT_TRUE(fs::is_directory(core)) << core;
  const std::regex include_line(R"(^\s*#\s*include\s*([<"])([^>"]+)[>"])");
  size_t files = 0;
  std::vector<std::string> offences;
  for (const auto& entry : fs::recursive_directory_iterator(core)) {
    const std::string ext = entry.path().extension().string();
    if (ext != ".cpp" && ext != ".hpp") continue;
    ++files;
    std::istringstream lines(read_text(entry.path()));
    std::string line;
    while (std::getline(lines, line)) {
      std::smatch m;
      if (std::regex_search(line, m, include_line) && !allowed_include(m[2], m[1] == "<")) {
        offences.push_back(entry.path().lexically_relative(core).string() + ": " + line);
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
  const std::regex link(R"(target_link_libraries\(\s*\$\{name\}([^)]*)\))");
  std::smatch m;
  ASSERT_TRUE(std::regex_search(cmake, m, link)) << "core's target_link_libraries not found";
  std::istringstream words(m[1].str());
  std::string word;
  while (words >> word) {
    EXPECT_TRUE(word == "PUBLIC" || word == "PRIVATE" || word == "Eigen3::Eigen" ||
                word == "vnsba_warnings")
        << "core/ links " << word;
  }
}

}  // namespace
