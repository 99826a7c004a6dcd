#include <unordered_set>
#include <vector>

#include "csgrt/csg/scene_file.h"
#include "limits.h"
#include "loader.h"

namespace csgrt::detail::scene_file {

namespace {

/// Builds the JSON tree from the parser's events, rejecting duplicate keys (nlohmann keeps the
/// last one silently) and nesting deeper than kMaxJsonDepth, each at its JSON pointer.
///
/// It replaces nlohmann's callback parser, which after every closed child scans its parent
/// for a discarded element (quadratic in the length of "objects"), and ordered_json's
/// `operator[]`, which finds a key by a linear search (quadratic in the number of materials
/// or definitions): a key is checked once against a hash set and appended. The pointer of the
/// current place is only assembled for a message.
class SceneTreeBuilder {
public:
    using String = Json::string_t;

    SceneTreeBuilder(Json& root, const Source& source) : root_(root), source_(source) {}

    bool null() { return place(Json(nullptr)); }
    bool boolean(bool value) { return place(Json(value)); }
    bool number_integer(Json::number_integer_t value) { return place(Json(value)); }
    bool number_unsigned(Json::number_unsigned_t value) { return place(Json(value)); }
    bool number_float(Json::number_float_t value, const String&) { return place(Json(value)); }
    bool string(String& value) { return place(Json(std::move(value))); }
    bool binary(Json::binary_t& value) { return place(Json::binary(std::move(value))); }

    bool start_object(std::size_t) { return open(Json::value_t::object); }
    bool start_array(std::size_t) { return open(Json::value_t::array); }
    bool end_object() { return close(); }
    bool end_array() { return close(); }

    bool key(String& key) {
        Frame& frame = frames_.back();
        if (!frame.keys.insert(key).second) {
            source_.fail(path() + "/" + escape_pointer_token(key),
                         "duplicate key " + quote_name(key) + " (JSON keeps only one of them)");
        }
        // The key is new: appended without ordered_map's linear search.
        auto& members =
            static_cast<Json::object_t::Container&>(*frame.value->get_ptr<Json::object_t*>());
        members.emplace_back(key, nullptr);
        frame.key = std::move(key);
        return true;
    }

    template <class Exception>
    bool parse_error(std::size_t, const std::string&, const Exception& error) {
        throw error;
    }

private:
    struct Frame {
        Json* value;
        std::size_t elements = 0;
        std::string key;
        std::unordered_set<std::string> keys;
    };

    /// Where the next value goes: the root, the last key's slot, or the end of an array.
    Json* slot() {
        if (frames_.empty()) return &root_;
        Frame& frame = frames_.back();
        ++frame.elements;
        if (frame.value->is_array()) {
            auto& elements = *frame.value->get_ptr<Json::array_t*>();
            elements.emplace_back();
            return &elements.back();
        }
        return &frame.value->get_ptr<Json::object_t*>()->back().second;
    }

    bool place(Json&& value) {
        count_value();
        *slot() = std::move(value);
        return true;
    }

    /// Fails once the file has more than kMaxJsonValues values, at the one past the limit.
    void count_value() {
        if (++values_ <= kMaxJsonValues) return;
        // The value's own pointer: it has not been put in its place yet.
        std::string at = path();
        if (!frames_.empty()) {
            const Frame& frame = frames_.back();
            at += '/';
            at += frame.value->is_array() ? std::to_string(frame.elements)
                                          : escape_pointer_token(frame.key);
        }
        source_.fail(at, "more than " + std::to_string(kMaxJsonValues) +
                             " JSON values (numbers, strings, arrays and objects; "
                             "docs/scene-format.md, Limits)");
    }

    bool open(Json::value_t type) {
        count_value();
        if (frames_.size() >= kMaxJsonDepth) {
            source_.fail(path(), "nesting deeper than " + std::to_string(kMaxJsonDepth) +
                                     " arrays and objects (docs/scene-format.md, Limits)");
        }
        Json* value = slot();
        *value = Json(type);
        frames_.push_back(Frame{value, 0, {}, {}});
        return true;
    }

    bool close() {
        frames_.pop_back();
        return true;
    }

    /// The pointer of the value being read.
    std::string path() const {
        std::string pointer;
        for (std::size_t i = 0; i + 1 < frames_.size(); ++i) {
            pointer += '/';
            pointer += frames_[i].value->is_array() ? std::to_string(frames_[i].elements - 1)
                                                    : escape_pointer_token(frames_[i].key);
        }
        return pointer;
    }

    Json& root_;
    const Source& source_;
    std::vector<Frame> frames_;
    std::size_t values_ = 0;
};

}  // namespace

Json parse_scene_json(std::string_view text, const Source& source) {
    Json root;
    try {
        SceneTreeBuilder builder(root, source);
        Json::sax_parse(text, &builder);
    } catch (const nlohmann::json::parse_error& error) {
        // what() is "[json.exception.parse_error.101] parse error at line 3, column 5: ...".
        std::string message = error.what();
        const auto start = message.find("] ");
        if (start != std::string::npos) message.erase(0, start + 2);
        throw SceneError(source.name + ": invalid JSON: " + message);
    } catch (const nlohmann::json::exception& error) {
        // A number too large for a double ("[json.exception.out_of_range.406] ...").
        std::string message = error.what();
        const auto start = message.find("] ");
        if (start != std::string::npos) message.erase(0, start + 2);
        throw SceneError(source.name + ": invalid JSON: " + message);
    }
    return root;
}

}  // namespace csgrt::detail::scene_file
