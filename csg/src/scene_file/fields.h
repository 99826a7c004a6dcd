#pragma once

// Reading one JSON object of a scene file: numbers, counts, vectors, colours, strings and arrays
// at their keys, each checked with a message at its JSON pointer, and unknown keys refused.

#include <algorithm>
#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

#include "csgrt/core/math.h"
#include "messages.h"

namespace csgrt::detail::scene_file {

/// One JSON object of the file, read key by key. Every key asked for is remembered, so
/// `finish` can reject the keys nobody asked for and list the ones that are known.
class Fields {
public:
    Fields(const Json& value, std::string pointer, const Source& source, std::string_view what);

    const Json& value() const { return value_; }
    const std::string& pointer() const { return pointer_; }
    std::string pointer(std::string_view key) const { return child_pointer(pointer_, key); }
    const Source& source() const { return source_; }
    const std::string& what() const { return what_; }
    void set_what(std::string what) { what_ = std::move(what); }

    bool has(std::string_view key) {
        ask(key);
        return value_.contains(key);
    }
    /// Whether `key` was asked for already.
    bool asked(std::string_view key) const {
        return std::find(asked_.begin(), asked_.end(), key) != asked_.end();
    }

    /// The raw value of a required key.
    const Json& required(std::string_view key, std::string_view expected);

    double number(std::string_view key) {
        return to_number(required(key, "a number"), pointer(key));
    }
    double number(std::string_view key, double fallback) {
        return has(key) ? number(key) : fallback;
    }
    /// An angle written in degrees, returned in radians.
    double degrees(std::string_view key, double fallback_degrees) {
        return number(key, fallback_degrees) * kPi / 180.0;
    }

    std::size_t count(std::string_view key) {
        return to_count(required(key, "a whole number"), pointer(key));
    }

    bool boolean(std::string_view key, bool fallback);

    std::string string(std::string_view key);
    std::string string(std::string_view key, const std::string& fallback) {
        return has(key) ? string(key) : fallback;
    }

    Vector3 vector(std::string_view key) {
        return to_vector(required(key, "an array of 3 numbers"), pointer(key));
    }
    Vector3 vector(std::string_view key, const Vector3& fallback) {
        return has(key) ? vector(key) : fallback;
    }
    /// A colour: an array of 3 numbers, or one number for a grey.
    Vector3 colour(std::string_view key, const Vector3& fallback);

    /// A required array (of anything); `minimum` elements at least.
    const Json& array(std::string_view key, std::size_t minimum, std::string_view of);

    /// Rejects every key that was not asked for, naming the known ones.
    void finish() const;

    [[noreturn]] void fail(std::string_view key, const std::string& message) const {
        source_.fail(key.empty() ? pointer_ : pointer(key), message);
    }

    /// `value` as a finite number, or a message at `at`.
    double to_number(const Json& value, const std::string& at) const;
    /// `value` as a whole number >= 0, or a message at `at`.
    std::size_t to_count(const Json& value, const std::string& at) const;
    /// `value` as an array of 3 finite numbers, or a message at `at`.
    Vector3 to_vector(const Json& value, const std::string& at) const;

private:
    void ask(std::string_view key) {
        if (std::find(asked_.begin(), asked_.end(), key) == asked_.end()) asked_.emplace_back(key);
    }

    const Json& value_;
    std::string pointer_;
    const Source& source_;
    std::string what_;
    std::vector<std::string> asked_;
};

}  // namespace csgrt::detail::scene_file
