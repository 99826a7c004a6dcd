#pragma once

// Reading one JSON object of a scene file: numbers, counts, vectors, colours, strings and arrays
// at their keys, each checked with a message at its JSON pointer, and unknown keys refused.

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
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
    Fields(const Json& value, JsonPointer pointer, const Source& source, std::string_view what);

    const Json& value() const { return value_; }
    const JsonPointer& pointer() const { return pointer_; }
    JsonPointer pointer(std::string_view key) const { return pointer_.child(key); }
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
        return to_number(required(key, "a number"), [&] { return pointer(key); });
    }
    double number(std::string_view key, double fallback) {
        return has(key) ? number(key) : fallback;
    }
    /// An angle written in degrees, returned in radians.
    double degrees(std::string_view key, double fallback_degrees) {
        return number(key, fallback_degrees) * kPi / 180.0;
    }

    std::size_t count(std::string_view key) {
        return to_count(required(key, "a whole number"), [&] { return pointer(key); });
    }

    bool boolean(std::string_view key, bool fallback);

    std::string string(std::string_view key);
    std::string string(std::string_view key, const std::string& fallback) {
        return has(key) ? string(key) : fallback;
    }

    Vector3 vector(std::string_view key) {
        return to_vector(required(key, "an array of 3 numbers"), [&] { return pointer(key); });
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

    // The conversions take where the value is either as a JsonPointer or as a function that
    // makes one, called only for a message: a value read without an error builds no pointer.

    /// `value` as a finite number, or a message at `at`.
    template <class At>
    double to_number(const Json& value, const At& at) const {
        if (!value.is_number()) source_.fail(at(), "expected a number, got " + describe(value));
        const double number = value.get<double>();
        // JSON has no NaN or infinity, but a literal like 1e999 overflows to infinity.
        if (!std::isfinite(number)) {
            source_.fail(at(), "expected a finite number, got " + value.dump());
        }
        return number;
    }
    double to_number(const Json& value, const JsonPointer& at) const {
        return to_number(value, [&] { return at; });
    }

    /// `value` as a whole number >= 0, or a message at `at`.
    template <class At>
    std::size_t to_count(const Json& value, const At& at) const {
        if (!value.is_number_integer() || value.get<std::int64_t>() < 0) {
            source_.fail(at(), "expected a whole number >= 0, got " + describe(value));
        }
        return value.get<std::size_t>();
    }
    std::size_t to_count(const Json& value, const JsonPointer& at) const {
        return to_count(value, [&] { return at; });
    }

    /// `value` as an array of 3 finite numbers, or a message at `at`.
    template <class At>
    Vector3 to_vector(const Json& value, const At& at) const {
        if (!value.is_array() || value.size() != 3) {
            source_.fail(at(), "expected an array of 3 numbers, got " + describe(value));
        }
        Vector3 vector;
        for (std::size_t i = 0; i < 3; ++i) {
            vector[static_cast<Eigen::Index>(i)] =
                to_number(value[i], [&] { return JsonPointer(at()).child(i); });
        }
        return vector;
    }
    Vector3 to_vector(const Json& value, const JsonPointer& at) const {
        return to_vector(value, [&] { return at; });
    }

private:
    void ask(std::string_view key) {
        if (std::find(asked_.begin(), asked_.end(), key) == asked_.end()) asked_.emplace_back(key);
    }

    const Json& value_;
    JsonPointer pointer_;
    const Source& source_;
    std::string what_;
    std::vector<std::string> asked_;
};

}  // namespace csgrt::detail::scene_file
