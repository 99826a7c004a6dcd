#include "messages.h"

#include <algorithm>
#include <cstdio>
#include <vector>

#include "csgrt/csg/scene_file.h"
#include "limits.h"

namespace csgrt::detail::scene_file {

std::string shown(std::string_view name) {
    std::string text;
    const std::string_view kept = name.substr(0, kLongestShownName);
    for (const char c : kept) {
        const auto byte = static_cast<unsigned char>(c);
        if (byte < 0x20 || byte == 0x7f) {
            char escaped[8];
            std::snprintf(escaped, sizeof escaped, "\\u%04x", byte);
            text += escaped;
        } else {
            text += c;
        }
    }
    if (name.size() > kept.size()) {
        text += "... (" + std::to_string(name.size()) + " bytes)";
    }
    return text;
}

std::string quote_name(std::string_view name) {
    // Appended piece by piece: GCC 12 warns falsely (-Wrestrict) on "\"" + string + "\"".
    std::string text = "\"";
    text.append(shown(name)).append("\"");
    return text;
}

std::string escape_pointer_token(std::string_view token) {
    std::string escaped;
    for (const char c : shown(token)) {
        if (c == '~') {
            escaped += "~0";
        } else if (c == '/') {
            escaped += "~1";
        } else {
            escaped += c;
        }
    }
    return escaped;
}

JsonPointer JsonPointer::child(std::string_view key) const {
    return JsonPointer(std::make_shared<const Step>(Step{step_, std::string(key), 0, false}));
}

JsonPointer JsonPointer::child(std::size_t index) const {
    return JsonPointer(std::make_shared<const Step>(Step{step_, {}, index, true}));
}

std::string JsonPointer::text() const {
    std::vector<const Step*> steps;
    for (const Step* step = step_.get(); step != nullptr; step = step->parent.get()) {
        steps.push_back(step);
    }
    std::string text;
    for (auto step = steps.rbegin(); step != steps.rend(); ++step) {
        text += '/';
        text +=
            (*step)->is_index ? std::to_string((*step)->index) : escape_pointer_token((*step)->key);
    }
    return text;
}

std::string with_article(std::string_view noun) {
    const bool vowel =
        !noun.empty() && std::string_view("aeiou").find(noun[0]) != std::string_view::npos;
    std::string text = vowel ? "an " : "a ";
    return text.append(shown(noun));
}

std::string describe(const Json& value) {
    switch (value.type()) {
        case Json::value_t::null:
            return "null";
        case Json::value_t::boolean:
            return value.get<bool>() ? "true" : "false";
        case Json::value_t::string:
            return "the string " + quote_name(value.get_ref<const std::string&>());
        case Json::value_t::array:
            return "an array of " + std::to_string(value.size());
        case Json::value_t::object:
            return "an object";
        default:
            return "the number " + value.dump();
    }
}

std::string shown_pointer(const std::string& pointer) {
    if (pointer.empty()) return "(top level)";
    constexpr std::size_t kKept = 120;
    if (pointer.size() <= 3 * kKept) return pointer;
    const std::size_t head = pointer.find('/', kKept);
    const std::size_t tail = pointer.rfind('/', pointer.size() - kKept);
    if (head == std::string::npos || tail == std::string::npos || tail <= head) return pointer;
    const auto levels = std::count(pointer.begin() + static_cast<std::ptrdiff_t>(head),
                                   pointer.begin() + static_cast<std::ptrdiff_t>(tail), '/');
    std::string text = pointer.substr(0, head);
    text.append("/...(").append(std::to_string(levels)).append(" levels)...");
    text.append(pointer.substr(tail));
    return text;
}

void Source::fail(const std::string& pointer, const std::string& message) const {
    std::string text = message;
    // Whatever of the file's text got into the message stays on one line.
    for (char& c : text) {
        if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) c = '?';
    }
    throw SceneError(name + ": " + shown_pointer(pointer) + ": " + text);
}

}  // namespace csgrt::detail::scene_file
