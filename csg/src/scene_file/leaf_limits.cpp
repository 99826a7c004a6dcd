// The expanded-leaf limit: every grid copy and every use of a definition counts, counted
// without building the expansion.

#include <unordered_set>

#include "limits.h"
#include "loader.h"

namespace csgrt::detail::scene_file {

std::uint64_t expanded_leaves(const Shape& shape,
                              std::unordered_map<const Shape*, std::uint64_t>& memo) {
    if (const auto found = memo.find(&shape); found != memo.end()) return found->second;
    const std::vector<const Shape*> children = shape.children();
    std::uint64_t leaves = children.empty() ? 1 : 0;
    for (const Shape* child : children)
        leaves = saturating_add(leaves, expanded_leaves(*child, memo));
    memo.emplace(&shape, leaves);
    return leaves;
}

void Loader::count_leaves(const Shape& shape, const JsonPointer& pointer) {
    total_leaves_ = saturating_add(total_leaves_, expanded_leaves(shape, leaves_));
    if (total_leaves_ > kMaxExpandedLeaves) {
        const std::string count = total_leaves_ == std::numeric_limits<std::uint64_t>::max()
                                      ? "at least 2^64 - 1"
                                      : std::to_string(total_leaves_);
        source_.fail(pointer, "the scene expands to " + count +
                                  " leaf shapes up to here (every grid copy and every use of a "
                                  "definition counts); at most " +
                                  std::to_string(kMaxExpandedLeaves) +
                                  " are allowed (docs/scene-format.md, Limits)");
    }
}

namespace {

/// Counts the expanded leaves the parsed file describes before anything is built, so a file
/// over kMaxExpandedLeaves is refused in time linear in its size instead of after building
/// legal inner structures (a 10^6-sphere grid inside a grid of 10). Each definition is counted
/// once (memoised by name); a node it does not understand counts as one leaf (a value that is
/// no object, none) and is left to the loader to report. Pointers are assembled from the stack
/// of tokens only for a message.
class LeafPrescan {
public:
    LeafPrescan(const Json& root, const DefinitionIndex& index, const Source& source)
        : root_(root), index_(index), source_(source) {
        if (const auto found = root.find("definitions");
            found != root.end() && found->is_object()) {
            definitions_ = &*found;
        }
    }

    /// Fails, with the loader's own messages and pointers, at the first grid whose copies
    /// pass the cap or at the object where the running total of the objects passes it.
    void run() {
        if (definitions_ != nullptr) {
            tokens_.push_back("definitions");
            for (auto it = definitions_->begin(); it != definitions_->end(); ++it) {
                definition(it.key(), it.value(), 0);
            }
            tokens_.pop_back();
        }
        const auto objects = root_.find("objects");
        if (objects == root_.end() || !objects->is_array()) return;
        tokens_.push_back("objects");
        std::uint64_t total = 0;
        for (std::size_t i = 0; i < objects->size(); ++i) {
            tokens_.push_back(std::to_string(i));
            total = saturating_add(total, node((*objects)[i], 0));
            if (total > kMaxExpandedLeaves) too_many(total);
            tokens_.pop_back();
        }
        tokens_.pop_back();
    }

private:
    std::uint64_t definition(const std::string& name, const Json& body, std::size_t depth) {
        if (const auto found = counted_.find(name); found != counted_.end()) return found->second;
        // A cycle is the loader's to report; it counts as one leaf here.
        if (!in_progress_.insert(name).second) return 1;
        tokens_.push_back(name);
        const std::uint64_t leaves = node(body, depth + 1);
        tokens_.pop_back();
        in_progress_.erase(name);
        counted_.emplace(name, leaves);
        return leaves;
    }

    std::uint64_t node(const Json& value, std::size_t depth) {
        // Deeper than the loader allows: the loader reports the depth.
        if (depth > kMaxShapeDepth) return 1;
        // Not a node at all: the loader refuses it where it meets it, so it adds no leaf (a
        // list of 10^7 zeros is "expected an object" at its first, not a count of leaves).
        if (!value.is_object()) return 0;
        const auto type = value.find("type");
        if (type == value.end() || !type->is_string()) return 1;
        const std::string& name = type->get_ref<const std::string&>();
        std::uint64_t leaves = 1;
        if (name == "union" || name == "intersection" || name == "difference") {
            leaves = list(value, "operands", depth);
        } else if (name == "compound") {
            leaves = list(value, "children", depth);
        } else if (name == "grid" || name == "array") {
            leaves = copies(value, name == "grid", depth);
        } else if (name == "not") {
            const auto operand = value.find("operand");
            if (operand == value.end()) return 1;
            tokens_.push_back("operand");
            leaves = node(*operand, depth + 1);
            tokens_.pop_back();
        } else if (name == "ref") {
            const auto target = value.find("definition");
            if (target != value.end() && target->is_string()) {
                const auto body = index_.find(target->get_ref<const std::string&>());
                if (body != index_.end()) {
                    // The definition's own tokens replace this node's in a message.
                    std::vector<std::string> saved = std::move(tokens_);
                    tokens_ = {"definitions"};
                    leaves =
                        definition(target->get_ref<const std::string&>(), *body->second, depth);
                    tokens_ = std::move(saved);
                }
            }
        }
        return leaves;
    }

    std::uint64_t list(const Json& value, const char* key, std::size_t depth) {
        const auto array = value.find(key);
        if (array == value.end() || !array->is_array()) return 1;
        std::uint64_t leaves = 0;
        tokens_.push_back(key);
        for (std::size_t i = 0; i < array->size(); ++i) {
            tokens_.push_back(std::to_string(i));
            leaves = saturating_add(leaves, node((*array)[i], depth + 1));
            tokens_.pop_back();
        }
        tokens_.pop_back();
        return leaves;
    }

    /// A grid's or an array's leaves: its copies (the product of a grid's counts, the length
    /// of an array's list) times its item's.
    std::uint64_t copies(const Json& value, bool is_grid, std::size_t depth) {
        const char* const key = is_grid ? "count" : "copies";
        const auto count = value.find(key);
        const auto item = value.find("item");
        if (count == value.end() || item == value.end() || !count->is_array()) return 1;
        std::uint64_t copies = is_grid ? 1 : count->size();
        for (const Json& axis : is_grid ? *count : Json::array()) {
            // Malformed counts are the loader's to report; whole numbers multiply, saturating.
            if (!axis.is_number_unsigned() && !axis.is_number_integer()) return 1;
            const auto n = axis.get<std::int64_t>();
            if (n <= 0) return 1;
            copies =
                static_cast<std::uint64_t>(n) > std::numeric_limits<std::uint64_t>::max() / copies
                    ? std::numeric_limits<std::uint64_t>::max()
                    : copies * static_cast<std::uint64_t>(n);
        }
        // Over one grid's or array's copy limit: the loader refuses it before building its
        // item.
        if (copies == 0 || copies > kMaxGridCopies) return 1;
        tokens_.push_back("item");
        const std::uint64_t item_leaves = node(*item, depth + 1);
        tokens_.pop_back();
        if (item_leaves != 0 && copies > kMaxExpandedLeaves / item_leaves) {
            tokens_.push_back(key);
            std::string message = count_text(copies);
            message.append(" copies of an item of ").append(std::to_string(item_leaves));
            message.append(" leaf shapes are more than the ");
            message.append(std::to_string(kMaxExpandedLeaves));
            message.append(" leaves a scene may expand to (docs/scene-format.md, Limits)");
            source_.fail(pointer(), message);
        }
        return copies * item_leaves;
    }

    /// A count for a message; the saturated count is a lower bound.
    static std::string count_text(std::uint64_t count) {
        return count == std::numeric_limits<std::uint64_t>::max() ? "at least 2^64 - 1"
                                                                  : std::to_string(count);
    }

    [[noreturn]] void too_many(std::uint64_t leaves) const {
        // Appended piece by piece: GCC 12 warns falsely (-Wrestrict) on chained string +.
        std::string message = "the scene expands to ";
        message.append(count_text(leaves));
        message.append(" leaf shapes up to here (every grid copy and every use of a definition ");
        message.append("counts); at most ").append(std::to_string(kMaxExpandedLeaves));
        message.append(" are allowed (docs/scene-format.md, Limits)");
        source_.fail(pointer(), message);
    }

    std::string pointer() const {
        std::string text;
        for (const std::string& token : tokens_)
            text.append("/").append(escape_pointer_token(token));
        return text;
    }

    const Json& root_;
    const DefinitionIndex& index_;
    const Source& source_;
    const Json* definitions_ = nullptr;
    std::unordered_map<std::string, std::uint64_t> counted_;
    std::unordered_set<std::string> in_progress_;
    std::vector<std::string> tokens_;
};

}  // namespace

void prescan_leaves(const Json& root, const DefinitionIndex& definitions, const Source& source) {
    LeafPrescan(root, definitions, source).run();
}

}  // namespace csgrt::detail::scene_file
