// STL: the structural scan of an ASCII or binary STL file.

#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include "mesh_scan.h"

namespace csgrt::detail {

namespace {

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

}  // namespace

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

}  // namespace csgrt::detail
