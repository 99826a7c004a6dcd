// PLY: the structural scan of an ASCII or binary PLY file (header, then every record).

#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include "mesh_scan.h"

namespace csgrt::detail {

namespace {

enum class PlyFormat { kAscii, kLittleEndian, kBigEndian };

struct PlyType {
    int size = 0;  // bytes
    bool is_float = false;
    bool is_signed = false;
};

struct PlyProperty {
    std::string name;
    PlyType type;
    bool is_list = false;
    PlyType count_type;
};

struct PlyElement {
    std::string name;
    std::size_t count = 0;
    std::size_t line = 0;
    std::vector<PlyProperty> properties;
};

bool ply_type(std::string_view name, PlyType& type) {
    struct Entry {
        std::string_view name;
        PlyType type;
    };
    static constexpr Entry kTypes[] = {
        {"char", {1, false, true}},    {"int8", {1, false, true}},    {"uchar", {1, false, false}},
        {"uint8", {1, false, false}},  {"short", {2, false, true}},   {"int16", {2, false, true}},
        {"ushort", {2, false, false}}, {"uint16", {2, false, false}}, {"int", {4, false, true}},
        {"int32", {4, false, true}},   {"uint", {4, false, false}},   {"uint32", {4, false, false}},
        {"float", {4, true, true}},    {"float32", {4, true, true}},  {"double", {8, true, true}},
        {"float64", {8, true, true}}};
    for (const Entry& entry : kTypes) {
        if (entry.name == name) {
            type = entry.type;
            return true;
        }
    }
    return false;
}

/// Decodes one binary PLY value of `type` to double (exact for every PLY type).
double decode(const unsigned char* bytes, const PlyType& type, bool swap) {
    unsigned char ordered[8];
    for (int i = 0; i < type.size; ++i) ordered[i] = bytes[swap ? type.size - 1 - i : i];
    if (type.is_float && type.size == 4) {
        float value;
        std::memcpy(&value, ordered, sizeof value);
        return value;
    }
    if (type.is_float) {
        double value;
        std::memcpy(&value, ordered, sizeof value);
        return value;
    }
    std::uint64_t raw = 0;
    std::memcpy(&raw, ordered, static_cast<std::size_t>(type.size));
    if (type.is_signed && type.size < 8 && (raw >> (8 * type.size - 1)) != 0) {
        raw |= ~std::uint64_t{0} << (8 * type.size);  // sign-extend
    }
    return type.is_signed ? double(static_cast<std::int64_t>(raw)) : double(raw);
}

struct PlyHeader {
    PlyFormat format = PlyFormat::kAscii;
    std::vector<PlyElement> elements;
    std::size_t lines = 0;
};

/// A PLY version number ("1.0", "1").
bool parse_version(std::string_view token, double& value) {
    const char* end = token.data() + token.size();
    const auto [stop, error] = std::from_chars(token.data(), end, value);
    return error == std::errc() && stop == end;
}

/// Parses the header (up to end_header) and checks that it describes a mesh OpenMesh reads:
/// a vertex element with float or double x, y, z, then a face element with an integer list
/// vertex_indices (or vertex_index); other elements only after the faces.
PlyHeader parse_ply_header(std::istream& in) {
    PlyHeader header;
    std::string line;
    bool has_format = false;
    constexpr std::size_t kLongestHeader = 4096;  // lines
    while (true) {
        if (!read_line(in, line, header.lines + 1))
            problem("truncated: the header has no end_header line");
        ++header.lines;
        if (header.lines > kLongestHeader) problem("no end_header in the first 4096 lines");
        if (!line.empty() && line.back() == '\r') line.pop_back();
        std::istringstream words(line);
        std::vector<std::string> tokens;
        for (std::string word; words >> word;) tokens.push_back(word);
        const std::size_t number = header.lines;
        if (number == 1) {
            if (tokens.size() != 1 || tokens[0] != "ply")
                problem("line 1: not a PLY file (no 'ply' magic)");
            continue;
        }
        if (tokens.empty()) continue;
        const std::string& keyword = tokens[0];
        if (keyword == "end_header") break;
        if (keyword == "comment" || keyword == "obj_info") continue;
        if (keyword == "format") {
            // OpenMesh and assimp read "1", "1.0" and "1.00" alike: the number is what counts.
            double version = 0.0;
            if (tokens.size() != 3 || !parse_version(tokens[2], version) || version != 1.0)
                problem_at_line(number, "expected 'format <type> 1.0'");
            if (tokens[1] == "ascii") {
                header.format = PlyFormat::kAscii;
            } else if (tokens[1] == "binary_little_endian") {
                header.format = PlyFormat::kLittleEndian;
            } else if (tokens[1] == "binary_big_endian") {
                header.format = PlyFormat::kBigEndian;
            } else {
                problem_at_line(number, "unknown format " + shown(tokens[1]));
            }
            has_format = true;
        } else if (keyword == "element") {
            long long count;
            if (tokens.size() != 3 || !parse_integer(tokens[2], count) || count < 0) {
                problem_at_line(number, "expected 'element <name> <count>'");
            }
            header.elements.push_back(
                PlyElement{tokens[1], static_cast<std::size_t>(count), number, {}});
        } else if (keyword == "property") {
            if (header.elements.empty()) problem_at_line(number, "property before any element");
            PlyProperty property;
            const bool list = tokens.size() == 5 && tokens[1] == "list";
            if (list) {
                property.is_list = true;
                if (!ply_type(tokens[2], property.count_type) ||
                    !ply_type(tokens[3], property.type) || property.count_type.is_float) {
                    problem_at_line(number, "bad list property types");
                }
                property.name = tokens[4];
            } else {
                if (tokens.size() != 3 || !ply_type(tokens[1], property.type)) {
                    problem_at_line(number, "expected 'property <type> <name>'");
                }
                property.name = tokens[2];
            }
            header.elements.back().properties.push_back(property);
        } else {
            problem_at_line(number, "unknown header keyword " + shown(keyword));
        }
    }
    if (!has_format) problem("the header has no format line");
    int vertex_element = -1, face_element = -1;
    for (std::size_t e = 0; e < header.elements.size(); ++e) {
        const PlyElement& element = header.elements[e];
        if (element.name == "vertex") {
            if (vertex_element >= 0) problem_at_line(element.line, "a second vertex element");
            vertex_element = static_cast<int>(e);
            for (const char* axis : {"x", "y", "z"}) {
                auto it = std::find_if(element.properties.begin(), element.properties.end(),
                                       [&](const PlyProperty& p) { return p.name == axis; });
                if (it == element.properties.end())
                    problem_at_line(element.line,
                                    std::string("the vertex element has no property ") + axis);
                if (it->is_list || !it->type.is_float) {
                    problem_at_line(element.line, std::string("vertex property ") + axis +
                                                      " must be float or double");
                }
            }
            for (const PlyProperty& p : element.properties) {
                if (p.is_list)
                    problem_at_line(element.line, "list property " + shown(p.name) +
                                                      " in the vertex element is not supported");
            }
        } else if (element.name == "face") {
            if (face_element >= 0) problem_at_line(element.line, "a second face element");
            if (vertex_element < 0)
                problem_at_line(element.line, "the face element comes before the vertex element");
            face_element = static_cast<int>(e);
            auto it = std::find_if(
                element.properties.begin(), element.properties.end(), [](const PlyProperty& p) {
                    return p.name == "vertex_indices" || p.name == "vertex_index";
                });
            if (it == element.properties.end() || !it->is_list || it->type.is_float) {
                problem_at_line(element.line,
                                "the face element has no integer list property vertex_indices");
            }
        } else if (face_element < 0) {
            problem_at_line(element.line, "element " + shown(element.name) +
                                              " before the faces is not supported");
        }
    }
    if (vertex_element < 0) problem("the header declares no vertex element");
    if (face_element < 0) problem("the header declares no face element");
    if (header.elements[static_cast<std::size_t>(face_element)].count == 0)
        problem("the header declares no faces");
    return header;
}

bool is_index_list(const PlyElement& element, const PlyProperty& property) {
    return element.name == "face" && property.is_list &&
           (property.name == "vertex_indices" || property.name == "vertex_index");
}

bool is_coordinate(const PlyElement& element, const PlyProperty& property) {
    return element.name == "vertex" &&
           (property.name == "x" || property.name == "y" || property.name == "z");
}

/// Walks the records of a binary PLY: every byte the header promises must be there, and no more.
void scan_ply_binary(std::istream& in, const PlyHeader& header, Expectation& expect) {
    const bool swap =
        (header.format == PlyFormat::kBigEndian) != (std::endian::native == std::endian::big);
    ByteReader bytes(in);
    unsigned char value[8];
    std::vector<long long> corners;
    for (const PlyElement& element : header.elements) {
        const std::size_t vertex_count = expect.vertices;
        for (std::size_t r = 0; r < element.count; ++r) {
            const Element id{element.name.c_str(), r};
            auto truncated = [&]() {
                problem("truncated: the file ends inside " + id.name() + " (the header, line " +
                        std::to_string(element.line) + ", declares " +
                        std::to_string(element.count) + ") at byte " +
                        std::to_string(bytes.position()));
            };
            for (const PlyProperty& property : element.properties) {
                if (!property.is_list) {
                    if (!bytes.read(value, static_cast<std::size_t>(property.type.size)))
                        truncated();
                    if (is_coordinate(element, property) &&
                        !std::isfinite(float(decode(value, property.type, swap)))) {
                        problem(id.name() + " has a non-finite coordinate " + property.name);
                    }
                    continue;
                }
                if (!bytes.read(value, static_cast<std::size_t>(property.count_type.size)))
                    truncated();
                const double count = decode(value, property.count_type, swap);
                const bool indices = is_index_list(element, property);
                if (count < 0 || (indices && count < 3)) {
                    problem(id.name() + " has a list of " +
                            std::to_string(static_cast<long long>(count)) + " " + property.name);
                }
                corners.clear();
                for (std::size_t k = 0; k < static_cast<std::size_t>(count); ++k) {
                    if (!bytes.read(value, static_cast<std::size_t>(property.type.size)))
                        truncated();
                    if (!indices) continue;
                    const auto index = static_cast<long long>(decode(value, property.type, swap));
                    if (index < 0 || static_cast<std::size_t>(index) >= vertex_count) {
                        problem(id.name() + " refers to vertex " + std::to_string(index) +
                                ", but the file has " + std::to_string(vertex_count) + " vertices");
                    }
                    corners.push_back(index);
                }
                if (indices) expect_face(expect, corners, false);
            }
        }
    }
    if (!bytes.at_end()) {
        problem("data after the last element at byte " + std::to_string(bytes.position()) +
                ": the header's counts do not match the file");
    }
}

/// Walks the records of an ASCII PLY, one record a line.
void scan_ply_ascii(std::istream& in, const PlyHeader& header, Expectation& expect) {
    LineReader lines(in);
    std::vector<long long> corners;
    for (const PlyElement& element : header.elements) {
        for (std::size_t r = 0; r < element.count; ++r) {
            const Element id{element.name.c_str(), r};
            if (!lines.next_nonblank()) {
                problem("truncated: the file ends before " + id.name() + " (the header, line " +
                        std::to_string(element.line) + ", declares " +
                        std::to_string(element.count) + ")");
            }
            const std::size_t line = lines.number() + header.lines;
            const auto& tokens = lines.tokens();
            std::size_t next = 0;
            auto take = [&]() -> std::string_view {
                if (next == tokens.size()) problem_at_line(line, id.name() + " has too few values");
                return tokens[next++];
            };
            for (const PlyProperty& property : element.properties) {
                if (!property.is_list) {
                    const std::string_view token = take();
                    if (is_coordinate(element, property)) {
                        coordinate(token, line, id);
                    } else {
                        float ignored;
                        if (!parse_float(token, ignored))
                            problem_at_line(line,
                                            id.name() + " has " + shown(token) + ", not a number");
                    }
                    continue;
                }
                long long count;
                const std::string_view count_token = take();
                if (!parse_integer(count_token, count) || count < 0) {
                    problem_at_line(line, id.name() + " has list size " + shown(count_token));
                }
                const bool indices = is_index_list(element, property);
                if (indices && count < 3)
                    problem_at_line(line, id.name() + " has " + std::to_string(count) + " corners");
                corners.clear();
                for (long long k = 0; k < count; ++k) {
                    const std::string_view token = take();
                    if (!indices) continue;
                    long long index;
                    if (!parse_integer(token, index))
                        problem_at_line(
                            line, id.name() + " has corner " + shown(token) + ", not an index");
                    check_corner(index, expect.vertices, line, id);
                    corners.push_back(index);
                }
                if (indices) expect_face(expect, corners, false);
            }
            if (next != tokens.size())
                problem_at_line(line, id.name() + " has more values than its properties");
        }
    }
    if (lines.next_nonblank()) {
        problem_at_line(lines.number() + header.lines,
                        "data after the last element: the header's counts do not match the file");
    }
}

}  // namespace

Expectation scan_ply(std::istream& in) {
    const PlyHeader header = parse_ply_header(in);
    Expectation expect;
    expect.binary = header.format != PlyFormat::kAscii;
    for (const PlyElement& element : header.elements) {
        if (element.name == "vertex") expect.vertices = element.count;
    }
    if (expect.binary) {
        scan_ply_binary(in, header, expect);
    } else {
        scan_ply_ascii(in, header, expect);
    }
    return expect;
}

}  // namespace csgrt::detail
