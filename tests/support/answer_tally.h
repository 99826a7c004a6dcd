#pragma once

#include <algorithm>

namespace csgrt::test {

/// Counts of a query's answers judged ray by ray against a reference (CGAL's exact predicates
/// or a long double model), for one case or, through add(), summed over many. Each test says
/// which rays and hits it takes; the judges that give an answer its verdict live with the tests.
struct AnswerTally {
    long rays = 0;
    /// Rays where the reference's answer changes within the ambiguity band (the precision the
    /// query is computed at cannot decide them): counted, not held against the answer.
    long ambiguous = 0;
    /// Judged rays the reference hits.
    long reference_hits = 0;
    /// Answers outside the band that disagree with the reference: bugs, so they must be zero.
    long false_hits = 0;
    long false_misses = 0;
    /// Hits whose t is farther from the reference's than the bound the test derives.
    long wrong_t = 0;
    /// |t - t_reference| / |t_reference| over the judged hits the test takes.
    double max_relative_error = 0.0;
    /// error / bound over judged hits, where the test has a bound: at most 1 while all agree.
    double max_ratio = 0.0;

    long disagreements() const { return false_hits + false_misses + wrong_t; }

    void add(const AnswerTally& other) {
        rays += other.rays;
        ambiguous += other.ambiguous;
        reference_hits += other.reference_hits;
        false_hits += other.false_hits;
        false_misses += other.false_misses;
        wrong_t += other.wrong_t;
        max_relative_error = std::max(max_relative_error, other.max_relative_error);
        max_ratio = std::max(max_ratio, other.max_ratio);
    }
};

}  // namespace csgrt::test
