#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "support/test_output.h"

namespace {

using csgrt::test::file_contents;

// docs/api.md shows the program the install test builds against an installed csgrt; this keeps
// the two the same, so the documented program is one that compiles and runs.
TEST(ApiDoc, ShowsTheInstallTestsConsumerProgramVerbatim) {
    const std::filesystem::path root(CSGRT_SOURCE_DIR);
    const std::string program = file_contents(root / "tests" / "install" / "consumer" / "main.cpp");
    const std::string doc = file_contents(root / "docs" / "api.md");
    const std::string code = program.substr(program.find("#include <csgrt/"));
    ASSERT_GT(code.size(), 500u);
    EXPECT_NE(doc.find("```cpp\n" + code + "```"), std::string::npos)
        << "docs/api.md no longer shows tests/install/consumer/main.cpp";
}

}  // namespace
