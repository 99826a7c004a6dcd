#pragma once

// Messages about a scene file: names and values from the file shown safely, JSON pointers, and
// the one place a SceneError is thrown from.

#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>

#include "csgrt/core/shape.h"

namespace csgrt::detail::scene_file {

// ordered_json keeps the file's order, so materials get indices in the order they are written.
using Json = nlohmann::ordered_json;
using ShapePointer = std::shared_ptr<const Shape>;

/// A name from the file for a message: control characters escaped, cut after
/// kLongestShownName bytes.
std::string shown(std::string_view name);

/// `shown`, in double quotes.
std::string quote_name(std::string_view name);

/// `token` as one step of a JSON pointer (RFC 6901: '~' and '/' escaped), shown safely.
std::string escape_pointer_token(std::string_view token);

/// A JSON pointer (RFC 6901, "/objects/3/radius") kept as a chain of steps, each sharing the
/// steps above it, and spelled out only when a message needs it: a level of the loader adds
/// one step in constant time and memory, so pointers cost memory and time linear in the
/// depth, not quadratic (a pointer 256 shape levels down was rebuilt, about 4 KB, per level).
class JsonPointer {
public:
    /// The whole document ("").
    JsonPointer() = default;

    /// The pointer to `key` of the object here, or to element `index` of the array here.
    JsonPointer child(std::string_view key) const;
    JsonPointer child(std::size_t index) const;

    /// "/objects/3/radius": each key escaped (escape_pointer_token), "" for the document.
    std::string text() const;

private:
    struct Step {
        std::shared_ptr<const Step> parent;
        /// A key of an object, or (when `is_index`) the index of an array element.
        std::string key;
        std::size_t index = 0;
        bool is_index = false;
    };
    explicit JsonPointer(std::shared_ptr<const Step> step) : step_(std::move(step)) {}

    std::shared_ptr<const Step> step_;
};

/// `noun` after "a" or "an" ("a sphere", "an array"), for what a node is in a message.
std::string with_article(std::string_view noun);

/// A JSON value in a few words, for "expected ..., got ..." messages.
std::string describe(const Json& value);

/// A pointer for a message: a very deep one (the nesting limits are met 500 levels down)
/// keeps its first and last 120 characters around the count of the levels left out.
std::string shown_pointer(const std::string& pointer);

/// Where in which file: everything a message needs besides what went wrong.
struct Source {
    std::string name;
    std::filesystem::path directory;

    /// Throws the SceneError "name: pointer: message".
    [[noreturn]] void fail(const std::string& pointer, const std::string& message) const;
    [[noreturn]] void fail(const JsonPointer& pointer, const std::string& message) const {
        fail(pointer.text(), message);
    }
};

}  // namespace csgrt::detail::scene_file
