#include "fields.h"

namespace csgrt::detail::scene_file {

Fields::Fields(const Json& value, JsonPointer pointer, const Source& source, std::string_view what)
    : value_(value), pointer_(std::move(pointer)), source_(source), what_(what) {
    if (!value_.is_object()) {
        source_.fail(pointer_, "expected an object (" + what_ + "), got " + describe(value_));
    }
}

const Json& Fields::required(std::string_view key, std::string_view expected) {
    ask(key);
    const auto found = value_.find(key);
    if (found == value_.end()) {
        source_.fail(pointer_, "missing required key \"" + std::string(key) + "\" (" +
                                   std::string(expected) + ") in " + what_);
    }
    return *found;
}

bool Fields::boolean(std::string_view key, bool fallback) {
    if (!has(key)) return fallback;
    const Json& value = value_.at(key);
    if (!value.is_boolean()) fail(key, "expected true or false, got " + describe(value));
    return value.get<bool>();
}

std::string Fields::string(std::string_view key) {
    const Json& value = required(key, "a string");
    if (!value.is_string()) fail(key, "expected a string, got " + describe(value));
    return value.get<std::string>();
}

Vector3 Fields::colour(std::string_view key, const Vector3& fallback) {
    if (!has(key)) return fallback;
    const Json& value = value_.at(key);
    const auto at = [&] { return pointer(key); };
    if (value.is_number()) return Vector3::Constant(to_number(value, at));
    return to_vector(value, at);
}

const Json& Fields::array(std::string_view key, std::size_t minimum, std::string_view of) {
    const Json& value = required(key, "an array of " + std::string(of));
    if (!value.is_array()) {
        fail(key, "expected an array of " + std::string(of) + ", got " + describe(value));
    }
    if (value.size() < minimum) {
        fail(key, "expected at least " + std::to_string(minimum) + " " + std::string(of) +
                      ", got " + std::to_string(value.size()));
    }
    return value;
}

void Fields::finish() const {
    for (auto it = value_.begin(); it != value_.end(); ++it) {
        if (std::find(asked_.begin(), asked_.end(), it.key()) != asked_.end()) continue;
        std::string message = "unknown key " + quote_name(it.key()) + " in " + what_;
        if (it.key() == "name") {
            message += " (\"name\" belongs to the top-level objects)";
        } else if (it.key() == "materials" || it.key() == "material_ramp") {
            message += " (\"" + it.key() + "\" belongs to grids and arrays)";
        }
        std::string known;
        for (const std::string& key : asked_) known += (known.empty() ? "" : ", ") + key;
        source_.fail(pointer(it.key()), message + "; expected one of: " + known);
    }
}

}  // namespace csgrt::detail::scene_file
