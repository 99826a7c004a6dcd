#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace {

std::string read_text(const std::filesystem::path& path) {
    std::ifstream file(path);
    std::ostringstream text;
    text << file.rdbuf();
    return text.str();
}

// docs/api.md shows the program the install test builds against an installed csgrt; this keeps
// the two the same, so the documented program is one that compiles and runs.
TEST(ApiDoc, ShowsTheInstallTestsConsumerProgramVerbatim) {
    const std::filesystem::path root(CSGRT_SOURCE_DIR);
    const std::string program = read_text(root / "tests" / "install" / "consumer" / "main.cpp");
    const std::string doc = read_text(root / "docs" / "api.md");
    const std::string code = program.substr(program.find("#include <csgrt/"));
    ASSERT_GT(code.size(), 500u);
    EXPECT_NE(doc.find("```cpp\n" + code + "```"), std::string::npos)
        << "docs/api.md no longer shows tests/install/consumer/main.cpp";
}

}  // namespace
