#include "csgrt/accel/mesh_io.h"

#include <Eigen/Geometry>
#include <OpenMesh/Core/IO/IOManager.hh>
#include <OpenMesh/Core/IO/importer/BaseImporter.hh>
#include <OpenMesh/Core/IO/reader/OBJReader.hh>
#include <OpenMesh/Core/IO/reader/OFFReader.hh>
#include <OpenMesh/Core/IO/reader/PLYReader.hh>
#include <OpenMesh/Core/IO/reader/STLReader.hh>

#include <algorithm>
#include <bit>
#include <charconv>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iostream>
#include <limits>
#include <span>
#include <sstream>
#include <streambuf>
#include <string_view>
#include <system_error>
#include <unordered_set>
#include <vector>

#include "csgrt/core/error.h"
#include "openmesh_session.h"

namespace csgrt {

namespace {

using Triangle = std::array<std::uint32_t, 3>;

// Errors and text parsing

/// Thrown by the format scans; load_mesh prefixes the file name.
struct FileProblem {
    std::string what;
};

[[noreturn]] void problem(std::string what) {
    throw FileProblem{std::move(what)};
}

[[noreturn]] void problem_at_line(std::size_t line, const std::string& what) {
    problem("line " + std::to_string(line) + ": " + what);
}

/// The value with its bytes in reverse order (for big-endian data).
template <class Value>
Value byte_swapped(Value value) {
    auto bytes = std::bit_cast<std::array<unsigned char, sizeof(Value)>>(value);
    std::reverse(bytes.begin(), bytes.end());
    return std::bit_cast<Value>(bytes);
}

std::string shown(std::string_view token) {
    constexpr std::size_t kLongest = 40;
    std::string text(token.substr(0, kLongest));
    for (char& c : text) {
        if (static_cast<unsigned char>(c) < 32 || static_cast<unsigned char>(c) > 126) c = '?';
    }
    return "'" + text + (token.size() > kLongest ? "...'" : "'");
}

/// The longest line a text mesh may have: a file of 2 GB without a newline must not be read
/// into one string. OpenMesh's readers hold a line at a time too.
constexpr std::size_t kLongestLine = 1u << 20;

/// Reads one line (without its '\n') into `line`, at most kLongestLine bytes; false at the
/// end of the file. `number` is the line's number, for the message.
bool read_line(std::istream& in, std::string& line, std::size_t number) {
    line.clear();
    std::streambuf& buffer = *in.rdbuf();
    bool read_any = false;
    for (int c = buffer.sbumpc(); c != std::char_traits<char>::eof(); c = buffer.sbumpc()) {
        read_any = true;
        if (c == '\n') return true;
        if (line.size() == kLongestLine) {
            problem_at_line(number, "longer than " + std::to_string(kLongestLine) +
                                        " bytes (1 MiB), the most a line may have");
        }
        line.push_back(static_cast<char>(c));
    }
    in.setstate(std::ios::eofbit);
    return read_any;
}

/// A text file read line by line, each line split at whitespace; it streams, holding one
/// line of at most kLongestLine bytes.
class LineReader {
public:
    explicit LineReader(std::istream& in) : in_(in) {}

    /// Reads the next line; false at the end of the file.
    bool next() {
        if (!read_line(in_, line_, number_ + 1)) return false;
        ++number_;
        tokens_.clear();
        std::size_t i = 0;
        while (i < line_.size()) {
            while (i < line_.size() && is_space(line_[i])) ++i;
            const std::size_t start = i;
            while (i < line_.size() && !is_space(line_[i])) ++i;
            if (i > start) tokens_.emplace_back(line_.data() + start, i - start);
        }
        return true;
    }
    /// Reads lines until one has a token; false at the end of the file.
    bool next_nonblank() {
        while (next()) {
            if (!tokens_.empty()) return true;
        }
        return false;
    }

    std::size_t number() const { return number_; }
    const std::vector<std::string_view>& tokens() const { return tokens_; }

private:
    static bool is_space(char c) {
        return c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v';
    }

    std::istream& in_;
    std::string line_;
    std::vector<std::string_view> tokens_;
    std::size_t number_ = 0;
};

/// Parses a whole token as a float (the precision OpenMesh 9's readers deliver). NaN and
/// infinity parse; callers reject them with their own message.
bool parse_float(std::string_view token, float& value) {
    if (!token.empty() && token.front() == '+') token.remove_prefix(1);
    const auto [end, error] = std::from_chars(token.data(), token.data() + token.size(), value);
    return error == std::errc() && end == token.data() + token.size();
}

bool parse_integer(std::string_view token, long long& value) {
    if (!token.empty() && token.front() == '+') token.remove_prefix(1);
    const auto [end, error] = std::from_chars(token.data(), token.data() + token.size(), value);
    return error == std::errc() && end == token.data() + token.size();
}

/// Names one element of a file ("vertex 3", "face 0"), built only when a message needs it.
struct Element {
    const char* kind;
    std::size_t index;
    std::string name() const { return std::string(kind) + " " + std::to_string(index); }
};

/// A coordinate token: must be a finite float.
float coordinate(std::string_view token, std::size_t line, const Element& element) {
    float value;
    if (!parse_float(token, value)) {
        problem_at_line(line, element.name() + " has coordinate " + shown(token) +
                                  ", which is not a number in float range");
    }
    if (!std::isfinite(value)) {
        problem_at_line(line, element.name() + " has a non-finite coordinate " + shown(token));
    }
    return value;
}

// What a structural scan expects OpenMesh to deliver

/// What the independent scan of a file found; OpenMesh's result must agree with it.
struct Expectation {
    bool binary = false;
    /// Faces stored in the file, and how many of them OpenMesh is expected to drop.
    std::size_t file_faces = 0;
    std::size_t dropped_faces = 0;
    /// Vertices OpenMesh must deliver (STL: unknown, its reader merges equal corners).
    std::size_t vertices = 0;
    bool vertices_known = true;
    /// The sum of the face sizes and of all face corner indices: a checksum of the faces that
    /// catches a reader that misparses or pads the data.
    std::uint64_t corners = 0;
    std::uint64_t index_sum = 0;
    bool corners_known = true;
    /// OBJ: every face's corners as written (0-based, repeats kept), flattened, and where each
    /// face starts. OpenMesh's OBJ reader keeps only the first occurrence of a repeated corner,
    /// which closes the hole of a keyhole polygon (the outer loop, a bridge, the hole, the
    /// bridge back), so OBJ faces are triangulated as written.
    std::vector<long long> written_corners;
    std::vector<std::size_t> written_starts;
};

/// Adds one face (corner indices already validated) to the checksums. `distinct_only` mirrors
/// OpenMesh's OBJ reader, which keeps only the first occurrence of a repeated corner and drops
/// faces left with fewer than three.
void expect_face(Expectation& expect, std::span<const long long> corners, bool distinct_only) {
    ++expect.file_faces;
    if (!distinct_only) {
        expect.corners += corners.size();
        for (long long index : corners) expect.index_sum += static_cast<std::uint64_t>(index);
        return;
    }
    // The distinct corners by sorting: a face of 10^5 corners costs a sort, not 10^10 finds.
    std::vector<long long> distinct(corners.begin(), corners.end());
    std::sort(distinct.begin(), distinct.end());
    distinct.erase(std::unique(distinct.begin(), distinct.end()), distinct.end());
    const std::size_t kept = distinct.size();
    std::uint64_t sum = 0;
    for (long long index : distinct) sum += static_cast<std::uint64_t>(index);
    if (kept < 3) {
        ++expect.dropped_faces;
        return;
    }
    expect.corners += kept;
    expect.index_sum += sum;
}

std::string vertex_name(std::size_t index) {
    return "vertex " + std::to_string(index);
}
std::string face_name(std::size_t index) {
    return "face " + std::to_string(index);
}

/// A face corner index read from the file (0-based after any conversion): must name a vertex.
void check_corner(long long index, std::size_t vertex_count, std::size_t line,
                  const Element& face) {
    if (index < 0 || static_cast<unsigned long long>(index) >= vertex_count) {
        problem_at_line(line, face.name() + " refers to vertex " + std::to_string(index) +
                                  ", but the file has " + std::to_string(vertex_count) +
                                  " vertices");
    }
}

// OFF

/// Checks an ASCII OFF file the way OpenMesh's reader consumes it: the keyword on line 1, the
/// three counts next, one vertex per line (x y z, then optional normal, colour, texture
/// coordinates), one face per line (n, n indices, optional colour), nothing after the faces.
Expectation scan_off(std::istream& in) {
    Expectation expect;
    LineReader lines(in);
    if (!lines.next() || lines.tokens().empty()) problem("line 1: empty, expected an OFF header");
    const std::string_view keyword = lines.tokens()[0];
    if (keyword.size() < 3 || keyword.substr(keyword.size() - 3) != "OFF") {
        problem("line 1: " + shown(keyword) + " is not an OFF header (OFF, COFF, NOFF, STOFF...)");
    }
    const std::string_view prefix = keyword.substr(0, keyword.size() - 3);
    if (prefix.find_first_of("4n") != std::string_view::npos) {
        problem("line 1: " + shown(keyword) + ": only 3-dimensional OFF is supported");
    }
    if (prefix.find_first_not_of("STCN") != std::string_view::npos) {
        problem("line 1: " + shown(keyword) + " is not an OFF header");
    }
    if (lines.tokens().size() > 1) {
        if (lines.tokens()[1] == "BINARY") problem("line 1: binary OFF is not supported");
        problem("line 1: the counts must be on their own line after " + shown(keyword));
    }
    if (!lines.next_nonblank()) problem("truncated: no vertex, face and edge counts after line 1");
    const std::size_t counts_line = lines.number();
    long long counts[3];
    if (lines.tokens().size() != 3 || !parse_integer(lines.tokens()[0], counts[0]) ||
        !parse_integer(lines.tokens()[1], counts[1]) ||
        !parse_integer(lines.tokens()[2], counts[2]) || counts[0] < 0 || counts[1] < 0 ||
        counts[2] < 0) {
        const std::string_view first = lines.tokens()[0];
        problem_at_line(counts_line, first.starts_with("#")
                                         ? "comments are not supported by OpenMesh's OFF reader"
                                         : "expected three counts (vertices faces edges)");
    }
    const auto vertex_count = static_cast<std::size_t>(counts[0]);
    const auto face_count = static_cast<std::size_t>(counts[1]);
    if (face_count == 0) problem_at_line(counts_line, "the header declares no faces");
    expect.vertices = vertex_count;

    for (std::size_t v = 0; v < vertex_count; ++v) {
        if (!lines.next_nonblank()) {
            problem("truncated: the header (line " + std::to_string(counts_line) + ") declares " +
                    std::to_string(vertex_count) + " vertices and " + std::to_string(face_count) +
                    " faces, but the file ends after " + std::to_string(v) + " vertices");
        }
        const auto& tokens = lines.tokens();
        if (tokens.size() < 3) {
            problem_at_line(lines.number(), vertex_name(v) + " has fewer than 3 coordinates");
        }
        for (int axis = 0; axis < 3; ++axis)
            coordinate(tokens[axis], lines.number(), Element{"vertex", v});
        for (std::size_t i = 3; i < tokens.size(); ++i) {
            float ignored;
            if (!parse_float(tokens[i], ignored)) {
                problem_at_line(lines.number(),
                                vertex_name(v) + " has " + shown(tokens[i]) + ", not a number");
            }
        }
    }
    std::vector<long long> corners;
    for (std::size_t f = 0; f < face_count; ++f) {
        if (!lines.next_nonblank()) {
            problem("truncated: the header (line " + std::to_string(counts_line) + ") declares " +
                    std::to_string(face_count) + " faces, but the file ends after " +
                    std::to_string(f));
        }
        const auto& tokens = lines.tokens();
        long long size;
        if (!parse_integer(tokens[0], size)) {
            problem_at_line(lines.number(), face_name(f) + " starts with " + shown(tokens[0]) +
                                                ", not a corner count");
        }
        if (size < 3) {
            problem_at_line(lines.number(),
                            face_name(f) + " has " + std::to_string(size) + " corners");
        }
        if (tokens.size() < static_cast<std::size_t>(size) + 1) {
            problem_at_line(lines.number(), face_name(f) + " declares " + std::to_string(size) +
                                                " corners but lists " +
                                                std::to_string(tokens.size() - 1));
        }
        corners.clear();
        for (long long k = 0; k < size; ++k) {
            long long index;
            if (!parse_integer(tokens[k + 1], index)) {
                problem_at_line(lines.number(), face_name(f) + " has corner " +
                                                    shown(tokens[k + 1]) + ", not an index");
            }
            check_corner(index, vertex_count, lines.number(), Element{"face", f});
            corners.push_back(index);
        }
        expect_face(expect, corners, false);
    }
    if (lines.next_nonblank()) {
        problem_at_line(lines.number(), "data after the " + std::to_string(face_count) +
                                            " faces the header (line " +
                                            std::to_string(counts_line) + ") declares");
    }
    return expect;
}

// OBJ

/// Splits an OBJ face corner "v", "v/vt", "v//vn" or "v/vt/vn" into its three indices (0 when
/// absent). False when a present part is not an integer.
bool split_obj_corner(std::string_view token, long long parts[3]) {
    parts[0] = parts[1] = parts[2] = 0;
    for (int part = 0; part < 3; ++part) {
        const std::size_t slash = token.find('/');
        const std::string_view text = token.substr(0, slash);
        if (!text.empty() && !parse_integer(text, parts[part])) return false;
        if (part == 0 && text.empty()) return false;
        if (slash == std::string_view::npos) return true;
        token.remove_prefix(slash + 1);
    }
    return false;  // more than two slashes
}

/// Checks an OBJ file: "v" lines with 3 (or 4) finite coordinates, "f" lines with at least 3
/// corners whose vertex, texture and normal indices (1-based, or negative = relative) exist.
/// Other statements are ignored, as OpenMesh does.
Expectation scan_obj(std::istream& in) {
    Expectation expect;
    LineReader lines(in);
    std::size_t vertices = 0, texture_coordinates = 0, normals = 0;
    // Positive indices may point forward; they are checked against the final counts.
    long long largest[3] = {0, 0, 0};
    std::size_t largest_line[3] = {0, 0, 0};
    std::vector<long long> corners;
    std::size_t face = 0;
    std::vector<std::string_view> tokens;
    while (lines.next()) {
        // A '#' starts a comment anywhere on the line.
        tokens = lines.tokens();
        const auto comment = std::find_if(tokens.begin(), tokens.end(),
                                          [](std::string_view t) { return t.starts_with("#"); });
        tokens.erase(comment, tokens.end());
        if (tokens.empty()) continue;
        if (tokens.back() == "\\")
            problem_at_line(lines.number(), "line continuations are not supported");
        const std::string_view keyword = tokens[0];
        if (keyword == "v") {
            const Element id{"vertex", vertices};
            if (tokens.size() < 4)
                problem_at_line(lines.number(), id.name() + " has fewer than 3 coordinates");
            for (int axis = 0; axis < 3; ++axis) coordinate(tokens[axis + 1], lines.number(), id);
            ++vertices;
        } else if (keyword == "vt") {
            ++texture_coordinates;
        } else if (keyword == "vn") {
            ++normals;
        } else if (keyword == "f") {
            const Element id{"face", face};
            if (tokens.size() < 4) {
                problem_at_line(lines.number(), id.name() + " has " +
                                                    std::to_string(tokens.size() - 1) + " corners");
            }
            corners.clear();
            for (std::size_t k = 1; k < tokens.size(); ++k) {
                long long parts[3];
                if (!split_obj_corner(tokens[k], parts)) {
                    problem_at_line(lines.number(), id.name() + " has corner " + shown(tokens[k]) +
                                                        ", not v, v/vt, v//vn or v/vt/vn");
                }
                const std::size_t counts[3] = {vertices, texture_coordinates, normals};
                const char* what[3] = {"vertex", "texture coordinate", "normal"};
                for (int part = 0; part < 3; ++part) {
                    long long& index = parts[part];
                    if (index == 0) {
                        if (part == 0)
                            problem_at_line(
                                lines.number(),
                                id.name() + " refers to vertex 0 (OBJ indices start at 1)");
                        continue;
                    }
                    if (index < 0) {
                        index += static_cast<long long>(counts[part]);
                        if (index < 0) {
                            problem_at_line(lines.number(), id.name() + " has relative " +
                                                                what[part] + " index " +
                                                                shown(tokens[k]) +
                                                                " before the first " + what[part]);
                        }
                    } else {
                        index -= 1;
                        if (index >= largest[part]) {
                            largest[part] = index;
                            largest_line[part] = lines.number();
                        }
                    }
                }
                corners.push_back(parts[0]);
            }
            expect_face(expect, corners, true);
            expect.written_starts.push_back(expect.written_corners.size());
            expect.written_corners.insert(expect.written_corners.end(), corners.begin(),
                                          corners.end());
            ++face;
        }
    }
    const std::size_t counts[3] = {vertices, texture_coordinates, normals};
    const char* plural[3] = {"vertices", "texture coordinates", "normals"};
    for (int part = 0; part < 3; ++part) {
        if (largest_line[part] != 0 && static_cast<std::size_t>(largest[part]) >= counts[part]) {
            problem_at_line(largest_line[part],
                            "a face refers to " + std::string(part == 0 ? "vertex" : plural[part]) +
                                " " + std::to_string(largest[part] + 1) + ", but the file has " +
                                std::to_string(counts[part]) + " " + plural[part]);
        }
    }
    if (face == 0) problem("no faces (no 'f' statement)");
    expect.vertices = vertices;
    return expect;
}

// Binary input

/// Buffered reads from a binary stream, counting the bytes consumed.
class ByteReader {
public:
    explicit ByteReader(std::istream& in) : in_(in), buffer_(1 << 20) {}

    /// Copies n bytes to `out`; false when the file ends first.
    bool read(void* out, std::size_t n) {
        auto* bytes = static_cast<char*>(out);
        while (n > 0) {
            if (begin_ == end_ && !refill()) return false;
            const std::size_t chunk = std::min(n, end_ - begin_);
            std::memcpy(bytes, buffer_.data() + begin_, chunk);
            begin_ += chunk;
            bytes += chunk;
            n -= chunk;
            position_ += chunk;
        }
        return true;
    }
    /// True when no byte is left.
    bool at_end() { return begin_ == end_ && !refill(); }
    std::uint64_t position() const { return position_; }

private:
    bool refill() {
        in_.read(buffer_.data(), static_cast<std::streamsize>(buffer_.size()));
        begin_ = 0;
        end_ = static_cast<std::size_t>(in_.gcount());
        return end_ > 0;
    }

    std::istream& in_;
    std::vector<char> buffer_;
    std::size_t begin_ = 0, end_ = 0;
    std::uint64_t position_ = 0;
};

// PLY

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

// STL

/// Counts a facet; OpenMesh's STL reader merges equal corners and drops facets whose corners
/// are not three distinct points.
void expect_facet(Expectation& expect, const float corners[9]) {
    ++expect.file_faces;
    auto same = [&](int i, int j) {
        return corners[3 * i] == corners[3 * j] && corners[3 * i + 1] == corners[3 * j + 1] &&
               corners[3 * i + 2] == corners[3 * j + 2];
    };
    if (same(0, 1) || same(1, 2) || same(0, 2)) ++expect.dropped_faces;
}

/// A binary STL is exactly 84 + 50 n bytes for the n facets its header declares.
void scan_stl_binary(std::istream& in, std::uint32_t facets, Expectation& expect) {
    in.seekg(84);
    ByteReader bytes(in);
    unsigned char record[50];
    for (std::uint32_t f = 0; f < facets; ++f) {
        if (!bytes.read(record, sizeof record)) problem("truncated: facet " + std::to_string(f));
        float corners[9];
        std::memcpy(corners, record + 12, sizeof corners);  // after the facet normal
        if constexpr (std::endian::native == std::endian::big) {
            for (float& c : corners) c = byte_swapped(c);
        }
        for (int i = 0; i < 9; ++i) {
            if (!std::isfinite(corners[i]))
                problem("facet " + std::to_string(f) + " has a non-finite coordinate");
        }
        expect_facet(expect, corners);
    }
}

/// Checks ASCII STL grammar: solid, then facets (facet normal / outer loop / 3 vertex lines /
/// endloop / endfacet), then endsolid and nothing after it.
void scan_stl_ascii(std::istream& in, Expectation& expect) {
    LineReader lines(in);
    auto expect_line = [&](std::string_view keyword, std::string_view what) {
        if (!lines.next_nonblank())
            problem("truncated: the file ends where " + std::string(what) + " is expected");
        if (lines.tokens()[0] != keyword) {
            problem_at_line(lines.number(), "expected " + std::string(what) + ", found " +
                                                shown(lines.tokens()[0]));
        }
    };
    expect_line("solid", "'solid'");
    std::size_t facet = 0;
    while (true) {
        if (!lines.next_nonblank())
            problem("truncated: no 'endsolid' after facet " + std::to_string(facet));
        const std::string_view keyword = lines.tokens()[0];
        if (keyword == "endsolid") {
            // Several solids one after the other (what exporters write for several parts) are
            // one mesh, as OpenMesh and assimp read them.
            if (!lines.next_nonblank()) break;
            if (lines.tokens()[0] != "solid") {
                problem_at_line(lines.number(),
                                "expected 'solid' or the end of the file after "
                                "'endsolid', found " +
                                    shown(lines.tokens()[0]));
            }
            continue;
        }
        if (keyword != "facet")
            problem_at_line(lines.number(),
                            "expected 'facet' or 'endsolid', found " + shown(keyword));
        const Element id{"facet", facet};
        expect_line("outer", "'outer loop'");
        float corners[9];
        for (int k = 0; k < 3; ++k) {
            expect_line("vertex", "'vertex' " + std::to_string(k + 1) + " of " + id.name());
            if (lines.tokens().size() != 4)
                problem_at_line(lines.number(), id.name() + " has a vertex without 3 coordinates");
            for (int axis = 0; axis < 3; ++axis) {
                corners[3 * k + axis] = coordinate(lines.tokens()[axis + 1], lines.number(), id);
            }
        }
        expect_line("endloop", "'endloop' (OpenMesh reads triangles only)");
        expect_line("endfacet", "'endfacet'");
        expect_facet(expect, corners);
        ++facet;
    }
    if (facet == 0) problem("no facets");
}

Expectation scan_stl(std::istream& in, std::uintmax_t file_size) {
    Expectation expect;
    expect.vertices_known = false;
    expect.corners_known = false;
    char start[84] = {};
    in.read(start, sizeof start);
    const auto got = static_cast<std::size_t>(in.gcount());
    std::uint32_t facets = 0;
    if (got == sizeof start) {
        std::memcpy(&facets, start + 80, 4);
        if constexpr (std::endian::native == std::endian::big) facets = byte_swapped(facets);
    }
    const std::uint64_t binary_size = 84 + 50 * std::uint64_t{facets};
    std::string_view text(start, got);
    text.remove_prefix(std::min(text.find_first_not_of(" \t\r\n"), text.size()));
    if (got == sizeof start && binary_size == file_size) {
        if (facets == 0) problem("the binary header declares no facets");
        expect.binary = true;
        scan_stl_binary(in, facets, expect);
    } else if (text.starts_with("solid")) {
        in.clear();
        in.seekg(0);
        scan_stl_ascii(in, expect);
    } else {
        problem("not a binary STL of the size its header promises (" + std::to_string(facets) +
                " facets take " + std::to_string(binary_size) + " bytes, the file has " +
                std::to_string(file_size) +
                ": truncated or corrupt), and not an ASCII STL (no 'solid' at the start)");
    }
    return expect;
}

// OpenMesh

/// Receives what an OpenMesh reader parses, without building a half-edge mesh (which would
/// reject non-manifold faces and so hide them from validation): vertices and polygons, raw.
class RecordingImporter final : public OpenMesh::IO::BaseImporter {
public:
    std::vector<Eigen::Vector3f> points;
    std::vector<int> corners;
    std::vector<std::size_t> face_starts;
    bool bad_handle = false;

    OpenMesh::VertexHandle add_vertex(const OpenMesh::Vec3f& p) override {
        points.emplace_back(p[0], p[1], p[2]);
        return OpenMesh::VertexHandle(static_cast<int>(points.size() - 1));
    }
    OpenMesh::VertexHandle add_vertex(const OpenMesh::Vec3d& p) override {
        return add_vertex(OpenMesh::Vec3f(float(p[0]), float(p[1]), float(p[2])));
    }
    OpenMesh::VertexHandle add_vertex() override { return add_vertex(OpenMesh::Vec3f(0, 0, 0)); }
    void set_point(OpenMesh::VertexHandle vertex, const OpenMesh::Vec3f& p) override {
        if (vertex.idx() < 0 || static_cast<std::size_t>(vertex.idx()) >= points.size()) {
            bad_handle = true;
            return;
        }
        points[static_cast<std::size_t>(vertex.idx())] = Eigen::Vector3f(p[0], p[1], p[2]);
    }
    OpenMesh::FaceHandle add_face(const VHandles& handles) override {
        face_starts.push_back(corners.size());
        for (const OpenMesh::VertexHandle& handle : handles) corners.push_back(handle.idx());
        return OpenMesh::FaceHandle(static_cast<int>(face_starts.size() - 1));
    }
    std::size_t face_count() const { return face_starts.size(); }
    std::span<const int> face(std::size_t f) const {
        const std::size_t end = f + 1 < face_starts.size() ? face_starts[f + 1] : corners.size();
        return {corners.data() + face_starts[f], end - face_starts[f]};
    }

    // Everything else a reader may report (normals, colours, texture coordinates, status,
    // half-edge connectivity) is not needed.
    OpenMesh::HalfedgeHandle add_edge(OpenMesh::VertexHandle, OpenMesh::VertexHandle) override {
        bad_handle = true;
        return OpenMesh::HalfedgeHandle();
    }
    OpenMesh::FaceHandle add_face(OpenMesh::HalfedgeHandle) override {
        bad_handle = true;
        return OpenMesh::FaceHandle();
    }
    void add_face_texcoords(OpenMesh::FaceHandle, OpenMesh::VertexHandle,
                            const std::vector<OpenMesh::Vec2f>&) override {}
    void add_face_texcoords(OpenMesh::FaceHandle, OpenMesh::VertexHandle,
                            const std::vector<OpenMesh::Vec3f>&) override {}
    void set_face_texindex(OpenMesh::FaceHandle, int) override {}
    void set_halfedge(OpenMesh::VertexHandle, OpenMesh::HalfedgeHandle) override {}
    void set_normal(OpenMesh::VertexHandle, const OpenMesh::Vec3f&) override {}
    void set_normal(OpenMesh::VertexHandle, const OpenMesh::Vec3d&) override {}
    void set_color(OpenMesh::VertexHandle, const OpenMesh::Vec3uc&) override {}
    void set_color(OpenMesh::VertexHandle, const OpenMesh::Vec4uc&) override {}
    void set_color(OpenMesh::VertexHandle, const OpenMesh::Vec3f&) override {}
    void set_color(OpenMesh::VertexHandle, const OpenMesh::Vec4f&) override {}
    void set_texcoord(OpenMesh::VertexHandle, const OpenMesh::Vec2f&) override {}
    void set_status(OpenMesh::VertexHandle, const OpenMesh::Attributes::StatusInfo&) override {}
    void set_next(OpenMesh::HalfedgeHandle, OpenMesh::HalfedgeHandle) override {}
    void set_face(OpenMesh::HalfedgeHandle, OpenMesh::FaceHandle) override {}
    void request_face_texcoords2D() override {}
    void set_texcoord(OpenMesh::HalfedgeHandle, const OpenMesh::Vec2f&) override {}
    void set_texcoord(OpenMesh::VertexHandle, const OpenMesh::Vec3f&) override {}
    void set_texcoord(OpenMesh::HalfedgeHandle, const OpenMesh::Vec3f&) override {}
    void set_status(OpenMesh::HalfedgeHandle, const OpenMesh::Attributes::StatusInfo&) override {}
    void set_color(OpenMesh::EdgeHandle, const OpenMesh::Vec3uc&) override {}
    void set_color(OpenMesh::EdgeHandle, const OpenMesh::Vec4uc&) override {}
    void set_color(OpenMesh::EdgeHandle, const OpenMesh::Vec3f&) override {}
    void set_color(OpenMesh::EdgeHandle, const OpenMesh::Vec4f&) override {}
    void set_status(OpenMesh::EdgeHandle, const OpenMesh::Attributes::StatusInfo&) override {}
    void set_normal(OpenMesh::FaceHandle, const OpenMesh::Vec3f&) override {}
    void set_normal(OpenMesh::FaceHandle, const OpenMesh::Vec3d&) override {}
    void set_color(OpenMesh::FaceHandle, const OpenMesh::Vec3uc&) override {}
    void set_color(OpenMesh::FaceHandle, const OpenMesh::Vec4uc&) override {}
    void set_color(OpenMesh::FaceHandle, const OpenMesh::Vec3f&) override {}
    void set_color(OpenMesh::FaceHandle, const OpenMesh::Vec4f&) override {}
    void set_status(OpenMesh::FaceHandle, const OpenMesh::Attributes::StatusInfo&) override {}
    void add_texture_information(int, std::string) override {}
    std::size_t n_vertices() const override { return points.size(); }
    std::size_t n_faces() const override { return face_starts.size(); }
    std::size_t n_edges() const override { return 0; }
};

// Triangulation

/// Ear clipping over a doubly linked ring of a polygon's corners, with the ear test limited to
/// the corners near the ear by a z-order (Morton) index, after Mapbox's earcut (Agafonkin,
/// https://github.com/mapbox/earcut, 2016; Eberly, "Triangulation by Ear Clipping", 2002 for
/// the method). A corner that blocks an ear must be reflex and inside it; a corner at the same
/// place as the ear's first corner does not block it, so a keyhole polygon (the outer loop, a
/// bridge, the hole and the bridge back, with the bridge's corners repeated) is clipped around
/// its hole. The corners looked at per ear are those whose Morton codes lie within the ear's
/// box, so polygons of 10^5 corners take milliseconds instead of the minutes of the quadratic
/// scan. Points are 2D, counter-clockwise.
class EarClipper {
public:
    EarClipper(const std::vector<Eigen::Vector2d>& points,
               std::vector<std::array<std::uint32_t, 3>>& out)
        : points_(points), out_(out), nodes_(points.size()) {
        const std::size_t n = points.size();
        Eigen::Vector2d lower = points[0], upper = points[0];
        for (const Eigen::Vector2d& p : points) {
            lower = lower.cwiseMin(p);
            upper = upper.cwiseMax(p);
        }
        lower_ = lower;
        const double size = (upper - lower).maxCoeff();
        inverse_size_ = size > 0.0 && std::isfinite(size) ? 32767.0 / size : 0.0;
        for (std::size_t i = 0; i < n; ++i) {
            Node& node = nodes_[i];
            node.prev = static_cast<int>((i + n - 1) % n);
            node.next = static_cast<int>((i + 1) % n);
            node.z = morton(points[i]);
        }
        // The z-order list: every corner sorted by Morton code.
        std::vector<int> order(n);
        for (std::size_t i = 0; i < n; ++i) order[i] = static_cast<int>(i);
        std::sort(order.begin(), order.end(),
                  [&](int a, int b) { return nodes_[a].z < nodes_[b].z; });
        for (std::size_t k = 0; k < n; ++k) {
            nodes_[order[k]].prev_z = k > 0 ? order[k - 1] : -1;
            nodes_[order[k]].next_z = k + 1 < n ? order[k + 1] : -1;
        }
    }

    /// Clips the ring; returns the corners left when no ear and no local fix remains (empty
    /// when the whole polygon was triangulated).
    std::vector<std::uint32_t> run() {
        std::vector<std::uint32_t> left;
        int ear = 0;
        int stop = ear;
        int pass = 0;
        while (nodes_[ear].prev != nodes_[ear].next) {
            const int prev = nodes_[ear].prev, next = nodes_[ear].next;
            if (is_ear(ear)) {
                emit(prev, ear, next);
                remove(ear);
                ear = nodes_[next].next;
                stop = ear;
                continue;
            }
            ear = next;
            if (ear != stop) continue;
            // A whole round without an ear: drop repeated and collinear corners, then cut off
            // locally self-intersecting pieces (earcut's passes 1 and 2); then give up.
            if (pass == 0) {
                ear = filter(ear);
            } else if (pass == 1) {
                ear = filter(cure_local_intersections(filter(ear)));
            } else {
                int p = ear;
                do {
                    left.push_back(static_cast<std::uint32_t>(p));
                    p = nodes_[p].next;
                } while (p != ear);
                break;
            }
            ++pass;
            stop = ear;
            if (ear < 0) break;
        }
        return left;
    }

private:
    struct Node {
        int prev = -1, next = -1, prev_z = -1, next_z = -1;
        std::uint32_t z = 0;
    };

    /// Twice the signed area of (a, b, c): positive when counter-clockwise.
    double cross(int a, int b, int c) const {
        const Eigen::Vector2d &pa = points_[a], &pb = points_[b], &pc = points_[c];
        return (pb.x() - pa.x()) * (pc.y() - pa.y()) - (pb.y() - pa.y()) * (pc.x() - pa.x());
    }
    bool same_place(int a, int b) const { return points_[a] == points_[b]; }

    std::uint32_t morton(const Eigen::Vector2d& p) const {
        auto spread = [](std::uint32_t v) {
            v = (v | (v << 8)) & 0x00FF00FFu;
            v = (v | (v << 4)) & 0x0F0F0F0Fu;
            v = (v | (v << 2)) & 0x33333333u;
            v = (v | (v << 1)) & 0x55555555u;
            return v;
        };
        const auto x = static_cast<std::uint32_t>((p.x() - lower_.x()) * inverse_size_);
        const auto y = static_cast<std::uint32_t>((p.y() - lower_.y()) * inverse_size_);
        return spread(x) | (spread(y) << 1);
    }

    void emit(int a, int b, int c) {
        out_.push_back({static_cast<std::uint32_t>(a), static_cast<std::uint32_t>(b),
                        static_cast<std::uint32_t>(c)});
    }

    void remove(int p) {
        Node& node = nodes_[p];
        nodes_[node.next].prev = node.prev;
        nodes_[node.prev].next = node.next;
        if (node.prev_z >= 0) nodes_[node.prev_z].next_z = node.next_z;
        if (node.next_z >= 0) nodes_[node.next_z].prev_z = node.prev_z;
    }

    /// Whether corner p, a reflex or collinear corner, lies in the closed ear (a, b, c) and is
    /// not a repetition of a (a keyhole's bridge end).
    bool blocks(int p, int a, int b, int c) const {
        if (p == a || p == b || p == c || same_place(p, a)) return false;
        if (!(cross(a, b, p) >= 0.0 && cross(b, c, p) >= 0.0 && cross(c, a, p) >= 0.0))
            return false;
        return cross(nodes_[p].prev, p, nodes_[p].next) <= 0.0;
    }

    bool is_ear(int b) const {
        const int a = nodes_[b].prev, c = nodes_[b].next;
        if (!(cross(a, b, c) > 0.0)) return false;  // reflex or collinear: not an ear
        const Eigen::Vector2d lower = points_[a].cwiseMin(points_[b]).cwiseMin(points_[c]);
        const Eigen::Vector2d upper = points_[a].cwiseMax(points_[b]).cwiseMax(points_[c]);
        const std::uint32_t z_min = morton(lower), z_max = morton(upper);
        auto in_box = [&](int p) {
            const Eigen::Vector2d& q = points_[p];
            return q.x() >= lower.x() && q.x() <= upper.x() && q.y() >= lower.y() &&
                   q.y() <= upper.y();
        };
        // Every corner in the box has a Morton code in [z_min, z_max]: walk both ways from
        // the ear's own code.
        for (int p = nodes_[b].prev_z; p >= 0 && nodes_[p].z >= z_min; p = nodes_[p].prev_z) {
            if (in_box(p) && blocks(p, a, b, c)) return false;
        }
        for (int p = nodes_[b].next_z; p >= 0 && nodes_[p].z <= z_max; p = nodes_[p].next_z) {
            if (in_box(p) && blocks(p, a, b, c)) return false;
        }
        return true;
    }

    /// Removes corners that repeat their successor's place or are collinear with their
    /// neighbours, starting at `start`; returns a corner still in the ring (-1: fewer than 3).
    int filter(int start) {
        if (start < 0) return start;
        int end = start, p = start;
        bool again;
        do {
            again = false;
            const int next = nodes_[p].next;
            if (same_place(p, next) || cross(nodes_[p].prev, p, next) == 0.0) {
                remove(p);
                p = end = nodes_[p].prev;
                if (p == nodes_[p].next || nodes_[p].prev == nodes_[p].next) return -1;
                again = true;
            } else {
                p = next;
            }
        } while (again || p != end);
        return end;
    }

    bool locally_inside(int a, int b) const {
        const int prev = nodes_[a].prev, next = nodes_[a].next;
        return cross(prev, a, next) > 0.0 ? cross(a, b, next) <= 0.0 && cross(a, prev, b) <= 0.0
                                          : cross(a, b, prev) > 0.0 || cross(a, next, b) > 0.0;
    }

    bool segments_cross(int p1, int q1, int p2, int q2) const {
        auto sign = [](double v) { return (v > 0.0) - (v < 0.0); };
        auto on_segment = [&](int p, int q, int r) {
            const Eigen::Vector2d &a = points_[p], &b = points_[q], &c = points_[r];
            return b.x() <= std::max(a.x(), c.x()) && b.x() >= std::min(a.x(), c.x()) &&
                   b.y() <= std::max(a.y(), c.y()) && b.y() >= std::min(a.y(), c.y());
        };
        const int o1 = sign(cross(p1, q1, p2)), o2 = sign(cross(p1, q1, q2));
        const int o3 = sign(cross(p2, q2, p1)), o4 = sign(cross(p2, q2, q1));
        if (o1 != o2 && o3 != o4) return true;
        return (o1 == 0 && on_segment(p1, p2, q1)) || (o2 == 0 && on_segment(p1, q2, q1)) ||
               (o3 == 0 && on_segment(p2, p1, q2)) || (o4 == 0 && on_segment(p2, q1, q2));
    }

    /// Where the ring crosses itself over one corner (a, p, p.next, b with ap crossing
    /// p.next b), cuts off the triangle (a, p, b).
    int cure_local_intersections(int start) {
        if (start < 0) return start;
        int p = start;
        do {
            const int a = nodes_[p].prev, b = nodes_[nodes_[p].next].next;
            if (!same_place(a, b) && segments_cross(a, p, nodes_[p].next, b) &&
                locally_inside(a, b) && locally_inside(b, a)) {
                emit(a, p, b);
                cut_crossings_ = true;
                remove(nodes_[p].next);
                remove(p);
                p = start = b;
            }
            p = nodes_[p].next;
        } while (p != start && nodes_[p].prev != nodes_[p].next);
        return p;
    }

public:
    /// Whether a self-crossing of the ring was cut off (the polygon was not simple).
    bool cut_crossings() const { return cut_crossings_; }

private:
    const std::vector<Eigen::Vector2d>& points_;
    std::vector<std::array<std::uint32_t, 3>>& out_;
    bool cut_crossings_ = false;
    std::vector<Node> nodes_;
    Eigen::Vector2d lower_;
    double inverse_size_ = 0.0;
};

/// Splits a polygon into triangles in the plane of its Newell normal, keeping its winding:
/// EarClipper's ear clipping, which keeps repeated corners, so a face written as a keyhole
/// (a hole joined to the outer loop by a bridge) keeps its hole. Returns false when the
/// polygon was not simple: its edges cross (a crossing was cut off) or it collapses, or
/// corners were left that no ear could take and were fanned. Its triangles' area may then
/// differ from the polygon's; the fan's degenerate triangles are dropped by validation.
bool triangulate(std::span<const std::uint32_t> polygon,
                 const std::vector<Eigen::Vector3d>& vertices, std::vector<Triangle>& triangles) {
    const std::size_t n = polygon.size();
    if (n == 3) {
        triangles.push_back({polygon[0], polygon[1], polygon[2]});
        return true;
    }
    auto fan = [&](std::span<const std::uint32_t> corners) {
        for (std::size_t k = 1; k + 1 < corners.size(); ++k) {
            triangles.push_back({corners[0], corners[k], corners[k + 1]});
        }
    };
    Eigen::Vector3d normal = Eigen::Vector3d::Zero();
    for (std::size_t i = 0; i < n; ++i) {
        const Eigen::Vector3d& a = vertices[polygon[i]];
        const Eigen::Vector3d& b = vertices[polygon[(i + 1) % n]];
        normal +=
            Eigen::Vector3d((a.y() - b.y()) * (a.z() + b.z()), (a.z() - b.z()) * (a.x() + b.x()),
                            (a.x() - b.x()) * (a.y() + b.y()));
    }
    if (!(normal.squaredNorm() > 0.0)) {
        fan(polygon);
        return false;
    }
    // Project along the dominant normal axis; (x, y, axis) is a cyclic order, so the projected
    // polygon is counter-clockwise exactly when normal[axis] > 0. Mirror it otherwise.
    int axis;
    normal.cwiseAbs().maxCoeff(&axis);
    const int x = (axis + 1) % 3, y = (axis + 2) % 3;
    const double mirror = normal[axis] > 0.0 ? 1.0 : -1.0;
    std::vector<Eigen::Vector2d> points(n);
    for (std::size_t i = 0; i < n; ++i) {
        const Eigen::Vector3d& p = vertices[polygon[i]];
        points[i] = Eigen::Vector2d(p[x], mirror * p[y]);
    }
    std::vector<std::array<std::uint32_t, 3>> corners;
    corners.reserve(n - 2);
    EarClipper clipper(points, corners);
    const std::vector<std::uint32_t> left = clipper.run();
    for (const auto& t : corners)
        triangles.push_back({polygon[t[0]], polygon[t[1]], polygon[t[2]]});
    if (left.size() < 3) return !clipper.cut_crossings();
    std::vector<std::uint32_t> rest;
    for (std::uint32_t i : left) rest.push_back(polygon[i]);
    fan(rest);
    return false;
}

// Validation

constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();
constexpr std::uint32_t kSameDirection = 1u << 31;

/// Signed volume of the tetrahedron (reference, a, b, c) times 6; positive when a, b, c wind
/// counter-clockwise seen from outside it.
double volume6(const Eigen::Vector3d& reference, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
               const Eigen::Vector3d& c) {
    return (a - reference).dot((b - reference).cross(c - reference));
}

/// Whether the ray o + t d (t > 0) crosses triangle (a, b, c): Moeller and Trumbore, "Fast,
/// Minimum Storage Ray/Triangle Intersection", JGT 2(1) 1997. Only used to find how closed
/// shells nest, once per shell at load time.
bool ray_crosses(const Eigen::Vector3d& o, const Eigen::Vector3d& d, const Eigen::Vector3d& a,
                 const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
    const Eigen::Vector3d e1 = b - a, e2 = c - a;
    const Eigen::Vector3d p = d.cross(e2);
    const double determinant = e1.dot(p);
    if (determinant == 0.0) return false;
    const double inverse = 1.0 / determinant;
    const Eigen::Vector3d s = o - a;
    const double u = s.dot(p) * inverse;
    if (u < 0.0 || u > 1.0) return false;
    const Eigen::Vector3d q = s.cross(e1);
    const double v = d.dot(q) * inverse;
    if (v < 0.0 || u + v > 1.0) return false;
    return e2.dot(q) * inverse > 0.0;
}

}  // namespace

MeshReport validate_mesh(TriangleMeshData& mesh) {
    constexpr std::string_view kWhat = "validate_mesh";
    auto& vertices = mesh.vertices;
    auto& triangles = mesh.triangles;
    const std::size_t vertex_count = vertices.size();
    for (std::size_t v = 0; v < vertex_count; ++v) {
        if (!vertices[v].allFinite()) require(false, kWhat, vertex_name(v), "finite", vertices[v]);
    }
    require(!triangles.empty(), kWhat, "triangles", "not empty", 0);
    require(vertex_count < kNone && triangles.size() < (std::size_t{1} << 30), kWhat, "mesh size",
            "below 2^32 vertices and 2^30 triangles", triangles.size());
    for (std::size_t f = 0; f < triangles.size(); ++f) {
        for (std::uint32_t index : triangles[f]) {
            if (index >= vertex_count) {
                require(false, kWhat, "triangle " + std::to_string(f),
                        "indices below the vertex count " + std::to_string(vertex_count), index);
            }
        }
    }
    MeshReport report;
    report.vertices = vertex_count;
    const std::size_t triangle_count = triangles.size();
    auto repeated = [&](const Triangle& t) { return t[0] == t[1] || t[1] == t[2] || t[0] == t[2]; };

    // Each undirected edge once: every triangle side with three distinct corners, sorted by
    // its end points, so the sides of one edge are adjacent (a sort, not a scan of the
    // triangles around a vertex per side, which is quadratic at the hub of a fan such as a
    // long polygon's triangulation). Repeated-corner triangles have no proper edges and take
    // no part in the topology; zero-area ones with distinct corners do (they may close a
    // T-junction). Manifold edges link their two triangles; the link says whether both
    // traverse the edge in the same direction (inconsistent winding).
    struct Side {
        std::uint32_t low, high, face;
        int k;
    };
    std::vector<Side> sides;
    sides.reserve(3 * triangle_count);
    for (std::size_t f = 0; f < triangle_count; ++f) {
        const Triangle& t = triangles[f];
        if (repeated(t)) continue;
        for (int k = 0; k < 3; ++k) {
            const std::uint32_t a = t[k], b = t[(k + 1) % 3];
            sides.push_back({std::min(a, b), std::max(a, b), static_cast<std::uint32_t>(f), k});
        }
    }
    std::sort(sides.begin(), sides.end(), [](const Side& x, const Side& y) {
        if (x.low != y.low) return x.low < y.low;
        if (x.high != y.high) return x.high < y.high;
        return x.face < y.face;
    });
    std::vector<std::uint32_t> neighbour(3 * triangle_count, kNone);
    for (std::size_t begin = 0; begin < sides.size();) {
        std::size_t end = begin + 1;
        while (end < sides.size() && sides[end].low == sides[begin].low &&
               sides[end].high == sides[begin].high) {
            ++end;
        }
        const std::size_t sharing = end - begin;
        ++report.edges;
        if (sharing == 1) {
            ++report.boundary_edges;
        } else if (sharing > 2) {
            ++report.non_manifold_edges;
        } else {
            const Side& first = sides[begin];
            const Side& second = sides[begin + 1];
            // Both sides start at the same corner: they run the same way.
            const bool same = triangles[first.face][first.k] == triangles[second.face][second.k];
            report.inconsistent_edges += same ? 1 : 0;
            const std::uint32_t flag = same ? kSameDirection : 0;
            neighbour[3 * first.face + first.k] = second.face | flag;
            neighbour[3 * second.face + second.k] = first.face | flag;
        }
        begin = end;
    }

    // Orientation: propagate a winding through each component and flip the side with fewer
    // triangles, so an authored winding survives when most of a component agrees with it.
    std::vector<std::uint32_t> component(triangle_count, kNone);
    std::vector<std::uint8_t> flip(triangle_count, 0);
    std::vector<std::uint32_t> component_seed;
    std::vector<std::uint8_t> component_orientable, component_invert;
    std::vector<std::uint32_t> stack;
    for (std::size_t seed = 0; seed < triangle_count; ++seed) {
        if (repeated(triangles[seed]) || component[seed] != kNone) continue;
        const auto id = static_cast<std::uint32_t>(component_seed.size());
        std::size_t size = 0, flipped = 0;
        bool orientable = true;
        component[seed] = id;
        stack.push_back(static_cast<std::uint32_t>(seed));
        while (!stack.empty()) {
            const std::uint32_t f = stack.back();
            stack.pop_back();
            ++size;
            flipped += flip[f];
            for (int k = 0; k < 3; ++k) {
                const std::uint32_t link = neighbour[3 * f + k];
                if (link == kNone) continue;
                const std::uint32_t g = link & ~kSameDirection;
                const std::uint8_t wanted = flip[f] ^ ((link & kSameDirection) ? 1 : 0);
                if (component[g] == kNone) {
                    component[g] = id;
                    flip[g] = wanted;
                    stack.push_back(g);
                } else if (flip[g] != wanted) {
                    orientable = false;
                }
            }
        }
        component_seed.push_back(static_cast<std::uint32_t>(seed));
        component_orientable.push_back(orientable);
        component_invert.push_back(2 * flipped > size);
        report.orientable = report.orientable && orientable;
    }
    const std::size_t component_count = component_seed.size();
    report.components = component_count;
    // From here on, flip[f] says whether triangle f has been turned over.
    for (std::size_t f = 0; f < triangle_count; ++f) {
        const std::uint32_t c = component[f];
        flip[f] = c != kNone && component_orientable[c] && flip[f] != component_invert[c];
        if (flip[f]) std::swap(triangles[f][1], triangles[f][2]);
    }
    report.is_closed =
        report.boundary_edges == 0 && report.non_manifold_edges == 0 && report.orientable;

    if (report.is_closed) {
        // Outward: a shell nested inside an even number of others bounds the solid from
        // outside and must enclose positive volume; inside an odd number it bounds a cavity.
        std::vector<double> volume(component_count, 0.0);
        for (std::size_t f = 0; f < triangle_count; ++f) {
            if (component[f] == kNone) continue;
            const Eigen::Vector3d& reference = vertices[triangles[component_seed[component[f]]][0]];
            const Triangle& t = triangles[f];
            volume[component[f]] +=
                volume6(reference, vertices[t[0]], vertices[t[1]], vertices[t[2]]) / 6.0;
        }
        std::vector<std::uint8_t> outward_negative(component_count, 0);
        constexpr double kNestingBudget = 2e8;  // triangle tests
        if (component_count == 1) {
            outward_negative[0] = volume[0] < 0.0;
        } else if (double(component_count) * double(triangle_count) <= kNestingBudget) {
            // A direction unlikely to run along an edge of a modelled mesh.
            const Eigen::Vector3d direction = Eigen::Vector3d(0.5773, 0.6391, 0.5082).normalized();
            std::vector<std::uint8_t> parity(component_count);
            for (std::size_t c = 0; c < component_count; ++c) {
                std::fill(parity.begin(), parity.end(), 0);
                const Eigen::Vector3d& origin = vertices[triangles[component_seed[c]][0]];
                for (std::size_t f = 0; f < triangle_count; ++f) {
                    const std::uint32_t other = component[f];
                    if (other == kNone || other == c) continue;
                    const Triangle& t = triangles[f];
                    if (ray_crosses(origin, direction, vertices[t[0]], vertices[t[1]],
                                    vertices[t[2]])) {
                        parity[other] ^= 1;
                    }
                }
                const auto depth = std::count(parity.begin(), parity.end(), 1);
                outward_negative[c] = (volume[c] < 0.0) == (depth % 2 == 0);
            }
        } else {
            // Too many shells to nest cheaply: turn the mesh over only if it encloses a
            // negative volume in total.
            double total = 0.0;
            for (double v : volume) total += v;
            std::fill(outward_negative.begin(), outward_negative.end(), total < 0.0);
        }
        for (std::size_t f = 0; f < triangle_count; ++f) {
            if (component[f] == kNone || !outward_negative[component[f]]) continue;
            std::swap(triangles[f][1], triangles[f][2]);
            flip[f] ^= 1;
        }
        for (std::size_t c = 0; c < component_count; ++c) {
            report.inverted_components += outward_negative[c];
            report.volume += outward_negative[c] ? -volume[c] : volume[c];
        }
    }

    report.flipped_triangles = static_cast<std::size_t>(std::count(flip.begin(), flip.end(), 1));

    // Drop zero-area triangles (exactly: the corner cross product is the zero vector).
    std::size_t kept = 0;
    for (std::size_t f = 0; f < triangle_count; ++f) {
        const Triangle& t = triangles[f];
        const Eigen::Vector3d area =
            (vertices[t[1]] - vertices[t[0]]).cross(vertices[t[2]] - vertices[t[0]]);
        if (repeated(t) || area.squaredNorm() == 0.0) continue;
        triangles[kept++] = t;
    }
    report.degenerate_triangles = triangle_count - kept;
    triangles.resize(kept);
    triangles.shrink_to_fit();
    report.triangles = kept;
    require(kept > 0, kWhat, "count of triangles with non-zero area", "> 0", kept);

    // Angle-weighted vertex normals: each triangle adds its unit normal times its angle at the
    // vertex, so the result does not depend on how the surface around it is triangulated.
    auto& normals = mesh.normals;
    normals.assign(vertex_count, Eigen::Vector3d::Zero());
    for (const Triangle& t : triangles) {
        const Eigen::Vector3d face_normal =
            (vertices[t[1]] - vertices[t[0]]).cross(vertices[t[2]] - vertices[t[0]]).normalized();
        for (int k = 0; k < 3; ++k) {
            const Eigen::Vector3d to_next = vertices[t[(k + 1) % 3]] - vertices[t[k]];
            const Eigen::Vector3d to_previous = vertices[t[(k + 2) % 3]] - vertices[t[k]];
            const double angle =
                std::atan2(to_next.cross(to_previous).norm(), to_next.dot(to_previous));
            normals[t[k]] += angle * face_normal;
        }
    }
    std::vector<std::uint8_t> referenced(vertex_count, 0);
    for (const Triangle& t : triangles) referenced[t[0]] = referenced[t[1]] = referenced[t[2]] = 1;
    report.unreferenced_vertices =
        static_cast<std::size_t>(std::count(referenced.begin(), referenced.end(), 0));
    // A normal can also cancel out (a vertex shared by two opposite-facing sheets); it stays zero.
    for (Eigen::Vector3d& normal : normals) {
        const double length = normal.norm();
        if (length > 0.0) normal /= length;
    }
    return report;
}

namespace {
/// Meshes are indexed by 32 bits and hold at most 2^30 triangles; a binary STL of 2^30
/// facets is 50 GiB, but no mesh the library can hold needs a text file beyond 4 GiB.
constexpr std::uintmax_t kMaxMeshFileBytes = std::uintmax_t{4} << 30;

[[noreturn]] void fail_file(const std::string& name, const std::string& what) {
    throw MeshError(name + ": " + what);
}
}  // namespace

TriangleMeshData load_mesh(const std::filesystem::path& path, MeshReport* report_out) {
    const std::string name = path.string();
    auto fail = [&](const std::string& what) { fail_file(name, what); };
    if (name.find('\0') != std::string::npos) {
        fail_file(shown(name), "the path contains a NUL byte, which no file name can");
    }
    std::error_code error;
    const auto status = std::filesystem::status(path, error);
    if (!std::filesystem::exists(status)) fail("no such file");
    if (!std::filesystem::is_regular_file(status)) {
        // Refused before opening: a FIFO would block and a device never end.
        fail(std::filesystem::is_directory(status) ? "a directory, not a regular file"
             : std::filesystem::is_fifo(status)    ? "a FIFO, not a regular file"
             : std::filesystem::is_character_file(status) || std::filesystem::is_block_file(status)
                 ? "a device, not a regular file"
                 : "not a regular file");
    }
    const std::uintmax_t size = std::filesystem::file_size(path, error);
    if (error) fail("cannot read its size: " + error.message());
    std::string extension = path.extension().string();
    std::transform(extension.begin(), extension.end(), extension.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    if (extension != ".off" && extension != ".obj" && extension != ".ply" && extension != ".stl") {
        fail("unsupported extension " + shown(extension) + " (expected .off, .obj, .ply or .stl)");
    }
    if (size == 0) fail("empty file");
    if (size > kMaxMeshFileBytes) {
        fail("the file has " + std::to_string(size) + " bytes; mesh files are at most " +
             std::to_string(kMaxMeshFileBytes) + " (4 GiB; docs/meshes.md)");
    }
    std::ifstream in(path, std::ios::binary);
    if (!in) fail("cannot open it for reading");

    MeshReport report;
    report.format = extension.substr(1);
    Expectation expect;
    try {
        if (extension == ".off") {
            expect = scan_off(in);
        } else if (extension == ".obj") {
            expect = scan_obj(in);
        } else if (extension == ".ply") {
            expect = scan_ply(in);
        } else {
            expect = scan_stl(in, size);
        }
    } catch (const FileProblem& found) {
        fail(found.what);
    }
    if (in.bad()) fail("read error");
    in.close();
    report.binary = expect.binary;
    report.faces = expect.file_faces;
    report.dropped_faces = expect.dropped_faces;

    // The file is well formed; OpenMesh parses it, and must deliver what the scan counted.
    RecordingImporter importer;
    {
        detail::OpenMeshSession session;
        OpenMesh::IO::BaseReader* reader = nullptr;
        if (extension == ".off") reader = &OpenMesh::IO::OFFReader();
        if (extension == ".obj") reader = &OpenMesh::IO::OBJReader();
        if (extension == ".ply") reader = &OpenMesh::IO::PLYReader();
        if (extension == ".stl") reader = &OpenMesh::IO::STLReader();
        // can_u_read also parses the header into the reader's options, which read() uses.
        if (!reader->can_u_read(name)) fail("OpenMesh's " + report.format + " reader refuses it");
        OpenMesh::IO::Options options;
        if (!reader->read(name, importer, options)) fail("OpenMesh could not read it");
    }
    const std::size_t face_count = importer.face_count();
    const std::size_t expected_faces = expect.file_faces - expect.dropped_faces;
    if (expected_faces == 0) fail("no face has three distinct corners");
    if (importer.bad_handle) fail("OpenMesh reported an invalid vertex handle");
    if (expect.vertices_known && importer.points.size() != expect.vertices) {
        fail("OpenMesh read " + std::to_string(importer.points.size()) +
             " vertices, the file has " + std::to_string(expect.vertices));
    }
    if (face_count != expected_faces) {
        fail("OpenMesh read " + std::to_string(face_count) + " faces, expected " +
             std::to_string(expected_faces));
    }
    std::uint64_t corners = 0, index_sum = 0;
    for (int index : importer.corners) {
        ++corners;
        index_sum += static_cast<std::uint64_t>(static_cast<long long>(index));
    }
    if (expect.corners_known && (corners != expect.corners || index_sum != expect.index_sum)) {
        fail("OpenMesh's faces disagree with the file's (corner count or indices)");
    }

    TriangleMeshData mesh;
    mesh.vertices.reserve(importer.points.size());
    for (std::size_t v = 0; v < importer.points.size(); ++v) {
        const Eigen::Vector3f& p = importer.points[v];
        if (!p.allFinite()) fail(vertex_name(v) + " has a non-finite coordinate");
        mesh.vertices.push_back(p.cast<double>());
    }
    mesh.triangles.reserve(face_count + face_count / 2);
    std::vector<std::uint32_t> polygon;
    // OBJ: the next face as the file wrote it. OpenMesh dropped those with fewer than three
    // distinct corners; the others must be OpenMesh's faces with their repeats put back.
    std::size_t written = 0;
    std::unordered_set<long long> seen;
    auto as_written = [&](std::size_t f) {
        for (; written < expect.written_starts.size(); ++written) {
            const std::size_t begin = expect.written_starts[written];
            const std::size_t end = written + 1 < expect.written_starts.size()
                                        ? expect.written_starts[written + 1]
                                        : expect.written_corners.size();
            seen.clear();
            std::size_t k = 0;
            bool agrees = true;
            for (std::size_t c = begin; c < end; ++c) {
                const long long index = expect.written_corners[c];
                if (!seen.insert(index).second) continue;
                agrees = agrees && k < polygon.size() && polygon[k] == index;
                ++k;
            }
            if (k < 3) continue;
            if (!agrees || k != polygon.size())
                fail("OpenMesh's " + face_name(f) + " disagrees with the file's");
            polygon.assign(expect.written_corners.begin() + static_cast<std::ptrdiff_t>(begin),
                           expect.written_corners.begin() + static_cast<std::ptrdiff_t>(end));
            ++written;
            return;
        }
        fail("OpenMesh read more faces than the file has");
    };
    for (std::size_t f = 0; f < face_count; ++f) {
        const std::span<const int> face = importer.face(f);
        if (face.size() < 3)
            fail(face_name(f) + " has " + std::to_string(face.size()) + " corners");
        polygon.clear();
        for (int index : face) {
            if (index < 0 || static_cast<std::size_t>(index) >= mesh.vertices.size()) {
                fail(face_name(f) + " refers to vertex " + std::to_string(index) +
                     ", but the file has " + std::to_string(mesh.vertices.size()) + " vertices");
            }
            polygon.push_back(static_cast<std::uint32_t>(index));
        }
        if (!expect.written_starts.empty()) as_written(f);
        report.triangulated_faces += polygon.size() > 3 ? 1 : 0;
        if (!triangulate(polygon, mesh.vertices, mesh.triangles)) ++report.non_simple_faces;
    }
    importer = RecordingImporter();
    const std::size_t triangle_count = mesh.triangles.size();
    if (triangle_count >= (std::size_t{1} << 30) || mesh.vertices.size() >= kNone) {
        fail("too large: " + std::to_string(triangle_count) + " triangles (at most 2^30 - 1) and " +
             std::to_string(mesh.vertices.size()) + " vertices (at most 2^32 - 2)");
    }
    try {
        MeshReport validation = validate_mesh(mesh);
        validation.format = report.format;
        validation.binary = report.binary;
        validation.faces = report.faces;
        validation.dropped_faces = report.dropped_faces;
        validation.triangulated_faces = report.triangulated_faces;
        validation.non_simple_faces = report.non_simple_faces;
        report = std::move(validation);
    } catch (const InvalidParameter&) {
        // Vertices and indices were checked above; what validation can still reject is a mesh
        // whose every triangle has zero area.
        fail("no triangle of non-zero area: all " + std::to_string(triangle_count) +
             " are degenerate");
    }
    if (report_out != nullptr) *report_out = std::move(report);
    return mesh;
}

void save_mesh(const std::filesystem::path& path, const TriangleMeshData& mesh) {
    const std::string name = path.string();
    // Written beside the target and renamed into place, so an interrupted write never leaves a
    // truncated file where a complete one is expected.
    std::filesystem::path temporary = path;
    temporary += ".partial";
    {
        std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
        if (!out) throw MeshError(name + ": cannot open for writing");
        out << "ply\nformat binary_little_endian 1.0\ncomment written by csgrt\n"
            << "element vertex " << mesh.vertices.size()
            << "\nproperty float x\nproperty float y\nproperty float z\n"
            << "element face " << mesh.triangles.size()
            << "\nproperty list uchar int vertex_indices\nend_header\n";
        auto put = [&](auto value) {
            if constexpr (std::endian::native == std::endian::big) value = byte_swapped(value);
            out.write(reinterpret_cast<const char*>(&value), sizeof value);
        };
        for (const Eigen::Vector3d& v : mesh.vertices) {
            for (int axis = 0; axis < 3; ++axis) put(static_cast<float>(v[axis]));
        }
        for (const Triangle& t : mesh.triangles) {
            put(std::uint8_t{3});
            for (std::uint32_t index : t) put(static_cast<std::int32_t>(index));
        }
        out.flush();
        if (!out) throw MeshError(name + ": write failed");
    }
    std::error_code error;
    std::filesystem::rename(temporary, path, error);
    if (error)
        throw MeshError(name + ": cannot move the written file into place: " + error.message());
}

std::string describe(const MeshReport& report) {
    std::ostringstream out;
    if (!report.format.empty()) out << report.format << (report.binary ? " (binary)" : "") << ", ";
    out << report.vertices << " vertices, " << report.triangles << " triangles";
    if (report.faces != 0) out << " from " << report.faces << " faces";
    if (report.triangulated_faces)
        out << " (" << report.triangulated_faces << " polygons triangulated)";
    if (report.welded_vertices) out << ", " << report.welded_vertices << " vertices welded";
    if (report.non_simple_faces) {
        out << ", " << report.non_simple_faces
            << " polygons not simple (edges cross or collapse: cut at the crossings or fanned)";
    }
    if (report.dropped_faces) out << ", " << report.dropped_faces << " faces dropped by the reader";
    if (report.degenerate_triangles)
        out << ", " << report.degenerate_triangles << " degenerate triangles dropped";
    if (report.unreferenced_vertices)
        out << ", " << report.unreferenced_vertices << " unreferenced vertices";
    out << ", " << report.components << (report.components == 1 ? " component" : " components");
    if (report.is_closed) {
        out << ", closed (volume " << report.volume << ")";
    } else {
        out << ", open: " << report.boundary_edges << " boundary and " << report.non_manifold_edges
            << " non-manifold edges" << (report.orientable ? "" : ", not orientable");
    }
    if (report.flipped_triangles) {
        out << ", " << report.flipped_triangles << " triangles re-oriented";
        if (report.inverted_components)
            out << " (" << report.inverted_components << " shells turned outward)";
    }
    return out.str();
}

}  // namespace csgrt
