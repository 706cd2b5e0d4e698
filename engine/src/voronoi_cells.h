#pragma once
/// \file
/// Convex cells of a Voronoi diagram clipped to a box, for the scenes that cut a solid into
/// pieces (the Bullet benchmark's convex pack). Internal to the engine.

#include <array>
#include <vector>

namespace kolize {

using Point3 = std::array<double, 3>;

/// The vertices of the Voronoi cell of every site, clipped to the box [lo, hi]: the box cut
/// by the bisecting plane of the site and every other site. Vertices closer than 1e-12 of
/// the box size are merged. O(sites^2 x vertices^2); meant for tens to hundreds of sites.
std::vector<std::vector<Point3>> voronoiCells(const std::vector<Point3>& sites, const Point3& lo,
                                              const Point3& hi);

/// The point `index` (from 1) of the Halton sequence in bases 2, 3 and 5, in [0, 1)^3.
Point3 haltonPoint(int index);

}  // namespace kolize
