#pragma once

#include <gtest/gtest.h>

#include <cstdio>
#include <mutex>
#include <string>
#include <vector>

namespace csgrt::test {

/// One row of the stress summary: what was tried on one subject (a shape, a structure, a mesh
/// format), the worst error measured against the reference (negative when the check is
/// yes/no, not a measurement) and how many cases failed.
struct SummaryRow {
    std::string test;
    std::string subject;
    long cases = 0;
    double worst_error = -1.0;
    std::string error_kind;
    long failures = 0;
};

/// Collects the rows of the stress tests that ran in this process and prints them as one table
/// when the program ends (a GoogleTest environment's TearDown). Running the stress tests in
/// one process (docs/accuracy.md gives the command) prints the whole summary; ctest, which runs
/// each test alone, prints each test's rows.
class StressSummary : public ::testing::Environment {
public:
    static StressSummary& instance() {
        static StressSummary* summary = [] {
            auto* created = new StressSummary;
            ::testing::AddGlobalTestEnvironment(created);  // GoogleTest owns it
            return created;
        }();
        return *summary;
    }

    void add(SummaryRow row) {
        const std::lock_guard lock(mutex_);
        rows_.push_back(std::move(row));
    }

    void TearDown() override {
        if (rows_.empty()) return;
        long cases = 0, failures = 0;
        std::printf("\n  stress summary\n  | test | subject | cases | worst error | failures |\n");
        for (const SummaryRow& row : rows_) {
            char error[64] = "-";
            if (row.worst_error >= 0.0) {
                std::snprintf(error, sizeof error, "%.2e %s", row.worst_error,
                              row.error_kind.c_str());
            }
            std::printf("  | %s | %s | %ld | %s | %ld |\n", row.test.c_str(), row.subject.c_str(),
                        row.cases, error, row.failures);
            cases += row.cases;
            failures += row.failures;
        }
        std::printf("  | all | %zu rows | %ld | | %ld |\n\n", rows_.size(), cases, failures);
    }

private:
    std::mutex mutex_;
    std::vector<SummaryRow> rows_;
};

/// Adds a row for the running test (its name is filled in).
inline void summarize(const std::string& subject, long cases, long failures,
                      double worst_error = -1.0, const std::string& error_kind = "") {
    const ::testing::TestInfo* info = ::testing::UnitTest::GetInstance()->current_test_info();
    const std::string test = info ? std::string(info->test_suite_name()) + "." + info->name() : "";
    StressSummary::instance().add({test, subject, cases, worst_error, error_kind, failures});
}

/// Failed assertions so far in the running test: the failure count of tests whose checks are
/// plain assertions rather than tallies.
inline long failed_assertions() {
    const ::testing::TestResult* result =
        ::testing::UnitTest::GetInstance()->current_test_info()->result();
    long failed = 0;
    for (int i = 0; i < result->total_part_count(); ++i) {
        failed += result->GetTestPartResult(i).failed() ? 1 : 0;
    }
    return failed;
}

}  // namespace csgrt::test
