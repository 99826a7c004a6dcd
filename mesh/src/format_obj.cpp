// OBJ: the structural scan of an OBJ file.

#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include "mesh_scan.h"

namespace csgrt::detail {

namespace {

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

}  // namespace

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
            const Element id{"normal", normals};
            if (tokens.size() < 4)
                problem_at_line(lines.number(), id.name() + " has fewer than 3 coordinates");
            Eigen::Vector3f normal;
            for (int axis = 0; axis < 3; ++axis)
                normal[axis] = coordinate(tokens[axis + 1], lines.number(), id);
            expect.normals.push_back(normal);
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
                const bool has_normal = parts[2] != 0;
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
                // parts[2] is 0-based now, or still 0 when the corner names no normal.
                expect.written_normals.push_back(has_normal ? parts[2] : -1);
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

}  // namespace csgrt::detail
