// OFF: the structural scan of an ASCII OFF file.

#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include "mesh_scan.h"

namespace csgrt::detail {

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

}  // namespace csgrt::detail
