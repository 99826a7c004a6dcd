#pragma once

// What the four format scans share (mesh/src/format_*.cpp, read by mesh_io.cpp): the error a
// scan throws, streaming line and byte readers, number parsing with messages, and the
// Expectation a scan hands to the loader, which OpenMesh's result must match.

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <bit>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <istream>
#include <limits>
#include <span>
#include <sstream>
#include <streambuf>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

namespace csgrt::detail {

using Triangle = std::array<std::uint32_t, 3>;

// Errors and text parsing

/// Thrown by the format scans; load_mesh prefixes the file name.
struct FileProblem {
    std::string what;
};

[[noreturn]] inline void problem(std::string what) {
    throw FileProblem{std::move(what)};
}

[[noreturn]] inline void problem_at_line(std::size_t line, const std::string& what) {
    problem("line " + std::to_string(line) + ": " + what);
}

/// The value with its bytes in reverse order (for big-endian data).
template <class Value>
Value byte_swapped(Value value) {
    auto bytes = std::bit_cast<std::array<unsigned char, sizeof(Value)>>(value);
    std::reverse(bytes.begin(), bytes.end());
    return std::bit_cast<Value>(bytes);
}

inline std::string shown(std::string_view token) {
    constexpr std::size_t kLongest = 40;
    std::string text(token.substr(0, kLongest));
    for (char& c : text) {
        if (static_cast<unsigned char>(c) < 32 || static_cast<unsigned char>(c) > 126) c = '?';
    }
    return "'" + text + (token.size() > kLongest ? "...'" : "'");
}

/// The longest line a text mesh may have: a file of 2 GB without a newline must not be read
/// into one string. OpenMesh's readers hold a line at a time too.
inline constexpr std::size_t kLongestLine = 1u << 20;

/// Reads one line (without its '\n') into `line`, at most kLongestLine bytes; false at the
/// end of the file. `number` is the line's number, for the message.
inline bool read_line(std::istream& in, std::string& line, std::size_t number) {
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
inline bool parse_float(std::string_view token, float& value) {
    if (!token.empty() && token.front() == '+') token.remove_prefix(1);
    const auto [end, error] = std::from_chars(token.data(), token.data() + token.size(), value);
    return error == std::errc() && end == token.data() + token.size();
}

inline bool parse_integer(std::string_view token, long long& value) {
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
inline float coordinate(std::string_view token, std::size_t line, const Element& element) {
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
    /// OBJ: the `vn` normals, and each written corner's normal index (0-based, -1 for none).
    std::vector<Eigen::Vector3f> normals;
    std::vector<long long> written_normals;
};

/// Adds one face (corner indices already validated) to the checksums. `distinct_only` mirrors
/// OpenMesh's OBJ reader, which keeps only the first occurrence of a repeated corner and drops
/// faces left with fewer than three.
inline void expect_face(Expectation& expect, std::span<const long long> corners,
                        bool distinct_only) {
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

inline std::string vertex_name(std::size_t index) {
    return "vertex " + std::to_string(index);
}
inline std::string face_name(std::size_t index) {
    return "face " + std::to_string(index);
}

/// A face corner index read from the file (0-based after any conversion): must name a vertex.
inline void check_corner(long long index, std::size_t vertex_count, std::size_t line,
                         const Element& face) {
    if (index < 0 || static_cast<unsigned long long>(index) >= vertex_count) {
        problem_at_line(line, face.name() + " refers to vertex " + std::to_string(index) +
                                  ", but the file has " + std::to_string(vertex_count) +
                                  " vertices");
    }
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

/// The independent structural scans, one per format (mesh/src/format_off.cpp, ...). Each
/// throws FileProblem at the first defect.
Expectation scan_off(std::istream& in);
Expectation scan_obj(std::istream& in);
Expectation scan_ply(std::istream& in);
Expectation scan_stl(std::istream& in, std::uintmax_t file_size);

}  // namespace csgrt::detail
