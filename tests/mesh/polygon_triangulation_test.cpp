// Polygons written as one face: keyholes (a hole joined to the outer loop by a bridge whose
// corners repeat), combs, spirals, long runs of collinear corners, and one polygon of 100,000
// corners, in every polygon format. The independent answer is the polygon's own area by the
// shoelace formula: on integer coordinates every product is exact in double, so the triangles'
// areas must sum to it exactly, and any triangle over a hole or outside the polygon shows.
// 100,000 corners is the size of the hostile-input item (issue 15): a circle with collinear
// midpoints, a square with a corner at every integer point of its sides, and a comb whose base
// must be fanned; ear clipping's search for corners inside an ear made the last two take 17 s
// until a kd-tree replaced it (docs/accuracy.md).

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "csgrt/core/math.h"
#include "csgrt/mesh/mesh_io.h"
#include "support/test_scale.h"

namespace csgrt {
namespace {

/// A polygon as one face: its corners (integer coordinates in the plane z = 0), and the face
/// as corner indices into them, repeats allowed (a keyhole lists the bridge's ends twice).
struct Polygon {
    std::string name;
    std::vector<Eigen::Vector2d> points;
    std::vector<std::uint32_t> face;
};

/// Twice the signed area by the shoelace formula, exact for these integer coordinates.
double twice_area(const Polygon& polygon) {
    double sum = 0.0;
    for (std::size_t k = 0; k < polygon.face.size(); ++k) {
        const Eigen::Vector2d& a = polygon.points[polygon.face[k]];
        const Eigen::Vector2d& b = polygon.points[polygon.face[(k + 1) % polygon.face.size()]];
        sum += a.x() * b.y() - a.y() * b.x();
    }
    return sum;
}

Polygon from_loop(std::string name, const std::vector<Eigen::Vector2d>& loop) {
    Polygon polygon{std::move(name), loop, {}};
    for (std::uint32_t i = 0; i < loop.size(); ++i) polygon.face.push_back(i);
    return polygon;
}

/// A rectangle with `holes` square holes in a row, each joined to the bottom edge by its own
/// bridge: walking the bottom edge, at each hole the bridge up, the hole clockwise and the
/// bridge back down, so each bridge's two ends repeat (a weakly simple polygon, the form of a
/// polygon with holes that exporters write as one face).
Polygon keyhole(int holes) {
    Polygon polygon{"keyhole with " + std::to_string(holes) + " holes", {{0, 0}}, {0}};
    auto add = [&](double x, double y) {
        polygon.points.emplace_back(x, y);
        return static_cast<std::uint32_t>(polygon.points.size() - 1);
    };
    const double width = 4.0 * holes + 2.0;
    for (int h = 0; h < holes; ++h) {
        const double lo = 4.0 * h + 1.0, hi = lo + 2.0;
        const std::uint32_t foot = add(lo, 0), entry = add(lo, 1);
        const std::uint32_t a = add(lo, 3), b = add(hi, 3), c = add(hi, 1);
        polygon.face.insert(polygon.face.end(), {foot, entry, a, b, c, entry, foot});
    }
    polygon.face.push_back(add(width, 0));
    polygon.face.push_back(add(width, 4));
    polygon.face.push_back(add(0, 4));
    return polygon;
}

/// A comb of `teeth` teeth (width 1, height 10, gaps 1) on a base of height 1, with
/// `collinear` extra corners along the base's bottom edge.
Polygon comb(int teeth, int collinear) {
    std::vector<Eigen::Vector2d> loop;
    const double width = 2.0 * teeth - 1.0;
    for (int k = 0; k <= collinear; ++k) loop.emplace_back(width * k / (collinear + 1), 0.0);
    loop.emplace_back(width, 0.0);
    for (int i = teeth - 1; i >= 0; --i) {
        loop.emplace_back(2.0 * i + 1.0, 11.0);
        loop.emplace_back(2.0 * i, 11.0);
        if (i > 0) {
            loop.emplace_back(2.0 * i, 1.0);
            loop.emplace_back(2.0 * i - 1.0, 1.0);
        }
    }
    // The base's corners at width k / (collinear + 1) are integers only for these counts.
    return from_loop("comb of " + std::to_string(teeth) + " teeth, " + std::to_string(collinear) +
                         " collinear corners",
                     loop);
}

/// A square spiral corridor of width 2 and `turns` left turns (arms 4, 4, 8, 8, 12, ...
/// along its centre line, so neighbouring arms are 2 apart): the right side forward, the left
/// side back, corners mitred.
Polygon spiral(int turns) {
    std::vector<Eigen::Vector2d> centre{{0, 0}};
    Eigen::Vector2d direction(1, 0);
    for (int k = 0; k <= turns; ++k) {
        centre.push_back(centre.back() + 4.0 * (k / 2 + 1) * direction);
        direction = Eigen::Vector2d(-direction.y(), direction.x());
    }
    auto side = [&](double half_width) {
        std::vector<Eigen::Vector2d> line;
        auto right = [](const Eigen::Vector2d& d) { return Eigen::Vector2d(d.y(), -d.x()); };
        for (std::size_t k = 0; k < centre.size(); ++k) {
            const Eigen::Vector2d in =
                (centre[k > 0 ? k : 1] - centre[k > 0 ? k - 1 : 0]).normalized();
            const Eigen::Vector2d out =
                k + 1 < centre.size() ? Eigen::Vector2d((centre[k + 1] - centre[k]).normalized())
                                      : in;
            const Eigen::Vector2d along = k == 0 ? out : in;
            line.push_back(centre[k] +
                           half_width * (right(along) + (k == 0 || k + 1 == centre.size()
                                                             ? Eigen::Vector2d(0, 0)
                                                             : right(out))));
        }
        return line;
    };
    std::vector<Eigen::Vector2d> loop = side(1.0);
    const std::vector<Eigen::Vector2d> left = side(-1.0);
    loop.insert(loop.end(), left.rbegin(), left.rend());
    return from_loop("spiral of " + std::to_string(turns) + " turns", loop);
}

/// A square of side `per_side` with a corner at every integer point of its boundary.
Polygon collinear_square(int per_side) {
    std::vector<Eigen::Vector2d> loop;
    const double s = per_side;
    for (int k = 0; k < per_side; ++k) loop.emplace_back(k, 0);
    for (int k = 0; k < per_side; ++k) loop.emplace_back(s, k);
    for (int k = 0; k < per_side; ++k) loop.emplace_back(s - k, s);
    for (int k = 0; k < per_side; ++k) loop.emplace_back(0, s - k);
    return from_loop("square with " + std::to_string(4 * per_side) + " corners", loop);
}

/// A polygon of 2 `half` corners on a circle of radius 5 10^6: `half` points rounded to even
/// integers, each followed by the midpoint of it and the next (an integer, exactly collinear
/// with both), so half the corners are collinear with their neighbours.
Polygon round_with_midpoints(int half) {
    std::vector<Eigen::Vector2d> loop;
    auto on_circle = [&](int k) {
        const double angle = 2.0 * kPi * k / half;
        return Eigen::Vector2d(2.0 * std::round(2.5e6 * std::cos(angle)),
                               2.0 * std::round(2.5e6 * std::sin(angle)));
    };
    for (int k = 0; k < half; ++k) {
        const Eigen::Vector2d p = on_circle(k), q = on_circle((k + 1) % half);
        loop.push_back(p);
        loop.push_back(0.5 * (p + q));
    }
    return from_loop("circle with " + std::to_string(2 * half) + " corners, half collinear", loop);
}

/// Writes the polygon as one face in `format`, in the plane z = 0 or (tilted) x = 0.
std::filesystem::path write(const Polygon& polygon, const std::string& format, bool tilted,
                            const std::filesystem::path& folder) {
    const std::filesystem::path path = folder / ("polygon." + format);
    std::ofstream out(path);
    out.precision(17);  // integers up to 10^7: every digit
    auto point = [&](const Eigen::Vector2d& p) {
        if (tilted) {
            out << "0 " << p.x() << " " << p.y() << "\n";
        } else {
            out << p.x() << " " << p.y() << " 0\n";
        }
    };
    const std::size_t n = polygon.points.size();
    if (format == "off") {
        out << "OFF\n" << n << " 1 0\n";
        for (const auto& p : polygon.points) point(p);
        out << polygon.face.size();
        for (std::uint32_t i : polygon.face) out << " " << i;
        out << "\n";
    } else if (format == "obj") {
        for (const auto& p : polygon.points) {
            out << "v ";
            point(p);
        }
        out << "f";
        for (std::uint32_t i : polygon.face) out << " " << i + 1;
        out << "\n";
    } else {
        out << "ply\nformat ascii 1.0\nelement vertex " << n
            << "\nproperty float x\nproperty float y\nproperty float z\nelement face 1\n"
               "property list int int vertex_indices\nend_header\n";
        for (const auto& p : polygon.points) point(p);
        out << polygon.face.size();
        for (std::uint32_t i : polygon.face) out << " " << i;
        out << "\n";
    }
    return path;
}

class PolygonTriangulation : public ::testing::Test {
protected:
    void SetUp() override {
        folder_ =
            std::filesystem::temp_directory_path() /
            ("csgrt_polygons_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) +
             "_" + ::testing::UnitTest::GetInstance()->current_test_info()->name());
        std::filesystem::create_directories(folder_);
    }
    void TearDown() override { std::filesystem::remove_all(folder_); }
    std::filesystem::path folder_;
};

/// Loads each polygon as one face in every format and both planes, and checks that the
/// triangles cover exactly its area.
void check_areas(const std::vector<Polygon>& polygons, const std::filesystem::path& folder,
                 const std::vector<std::string>& formats = {"off", "obj", "ply"},
                 const std::vector<bool>& planes = {false, true}) {
    std::printf("\n  | polygon | corners | format | triangles | exact area | triangles' area |\n");
    for (const Polygon& polygon : polygons) {
        const double expected = 0.5 * twice_area(polygon);
        ASSERT_GT(expected, 0.0) << polygon.name << " is wound clockwise";
        for (const std::string& format : formats) {
            for (const bool tilted : planes) {
                MeshReport report;
                const TriangleMeshData mesh =
                    load_mesh(write(polygon, format, tilted, folder), &report);
                double area = 0.0;
                for (const auto& t : mesh.triangles) {
                    const Eigen::Vector3d& a = mesh.vertices[t[0]];
                    area += 0.5 * (mesh.vertices[t[1]] - a).cross(mesh.vertices[t[2]] - a).norm();
                }
                // Integer coordinates below 2^24 (exact in float), products below 2^53: the
                // norm of an axis-aligned normal is exact, and so is the sum.
                EXPECT_EQ(area, expected)
                    << polygon.name << " as " << format << (tilted ? " (tilted)" : "");
                EXPECT_EQ(report.non_simple_faces, 0u) << polygon.name << " as " << format;
                EXPECT_EQ(report.triangulated_faces, 1u);
                if (!tilted) {
                    std::printf("  | %s | %zu | %s | %zu | %.1f | %.1f |\n", polygon.name.c_str(),
                                polygon.face.size(), format.c_str(), mesh.triangles.size(),
                                expected, area);
                }
            }
        }
    }
}

TEST_F(PolygonTriangulation, TrianglesCoverExactlyThePolygonInEveryFormat) {
    check_areas({keyhole(1), keyhole(3), comb(5, 0), comb(40, 9), spiral(9), spiral(40),
                 collinear_square(50)},
                folder_);
}

TEST_F(PolygonTriangulation, FacesOfAHundredThousandCornersCoverExactlyThePolygon) {
    // One format and plane here; every format and plane in the heavy test below. The sanitizer
    // build takes test::scaled() of the sizes.
    check_areas({collinear_square(test::scaled(25000, 50)), comb(test::scaled(25000, 40), 0),
                 round_with_midpoints(test::scaled(50000, 500))},
                folder_, {"off"}, {false});
}

TEST_F(PolygonTriangulation, HeavyLargeFacesCoverExactlyThePolygonInEveryFormat) {
    // Label "heavy" (the name): every format and plane, each a whole load of the file (the
    // square and the comb at 10^4 corners, where parsing rather than triangulation dominates).
    check_areas({collinear_square(test::scaled(2500, 50)), comb(test::scaled(2500, 40), 0),
                 round_with_midpoints(test::scaled(50000, 500))},
                folder_);
}

TEST_F(PolygonTriangulation, ASelfIntersectingFaceIsCountedAsNotSimple) {
    // A bow tie: its edges cross, so no triangulation of it has its area; the load report
    // must say so rather than pass it off as triangulated.
    const Polygon bow_tie = from_loop("bow tie", {{0, 0}, {4, 0}, {0, 4}, {4, 4}, {2, 7}});
    for (const std::string format : {"off", "obj", "ply"}) {
        MeshReport report;
        load_mesh(write(bow_tie, format, false, folder_), &report);
        EXPECT_EQ(report.non_simple_faces, 1u) << format;
        EXPECT_NE(describe(report).find("1 polygons not simple"), std::string::npos)
            << describe(report);
    }
}

}  // namespace
}  // namespace csgrt
