#include "voronoi_cells.h"

#include <algorithm>
#include <cmath>

namespace kolize {

namespace {

/// A half-space n.x <= d.
struct HalfSpace {
    Point3 normal;
    double offset;
};

/// A vertex of a convex polytope with the planes it lies on (sorted ids).
struct Vertex {
    Point3 point;
    std::vector<int> planes;
};

double dot(const Point3& a, const Point3& b) {
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

int sharedPlanes(const Vertex& a, const Vertex& b, std::vector<int>& shared) {
    shared.clear();
    std::set_intersection(a.planes.begin(), a.planes.end(), b.planes.begin(), b.planes.end(),
                          std::back_inserter(shared));
    return int(shared.size());
}

/// Cuts the polytope by half-space `id`: vertices outside go; every edge from an inside to
/// an outside vertex (two vertices sharing two planes) gives a new vertex on the plane.
void clip(std::vector<Vertex>& polytope, const HalfSpace& cut, int id, double tolerance) {
    std::vector<double> distance(polytope.size());
    bool anyOutside = false;
    for (std::size_t i = 0; i < polytope.size(); ++i) {
        distance[i] = dot(cut.normal, polytope[i].point) - cut.offset;
        anyOutside = anyOutside || distance[i] > tolerance;
    }
    if (!anyOutside) {
        return;
    }
    std::vector<Vertex> kept;
    std::vector<int> shared;
    for (std::size_t i = 0; i < polytope.size(); ++i) {
        if (distance[i] > tolerance) {
            continue;
        }
        kept.push_back(polytope[i]);
        if (distance[i] >= -tolerance) {
            kept.back().planes.push_back(id);  // on the plane
            std::sort(kept.back().planes.begin(), kept.back().planes.end());
            continue;
        }
        for (std::size_t j = 0; j < polytope.size(); ++j) {
            if (distance[j] <= tolerance || sharedPlanes(polytope[i], polytope[j], shared) < 2) {
                continue;
            }
            const double t = distance[i] / (distance[i] - distance[j]);
            Vertex made;
            for (int axis = 0; axis < 3; ++axis) {
                made.point[axis] = polytope[i].point[axis] +
                                   t * (polytope[j].point[axis] - polytope[i].point[axis]);
            }
            made.planes = shared;
            made.planes.push_back(id);
            std::sort(made.planes.begin(), made.planes.end());
            kept.push_back(made);
        }
    }
    // Merge duplicates (a new vertex can coincide with one on the plane).
    std::vector<Vertex> merged;
    for (const Vertex& vertex : kept) {
        bool found = false;
        for (Vertex& other : merged) {
            double gap = 0;
            for (int axis = 0; axis < 3; ++axis) {
                gap = std::max(gap, std::fabs(vertex.point[axis] - other.point[axis]));
            }
            if (gap <= tolerance) {
                std::vector<int> planes;
                std::set_union(other.planes.begin(), other.planes.end(), vertex.planes.begin(),
                               vertex.planes.end(), std::back_inserter(planes));
                other.planes = planes;
                found = true;
                break;
            }
        }
        if (!found) {
            merged.push_back(vertex);
        }
    }
    polytope.swap(merged);
}

}  // namespace

std::vector<std::vector<Point3>> voronoiCells(const std::vector<Point3>& sites, const Point3& lo,
                                              const Point3& hi) {
    double size = 0;
    for (int axis = 0; axis < 3; ++axis) {
        size = std::max(size, hi[axis] - lo[axis]);
    }
    const double tolerance = 1e-12 * size;
    std::vector<std::vector<Point3>> cells;
    for (std::size_t site = 0; site < sites.size(); ++site) {
        // The box: planes 0..5 (min and max per axis), its 8 corners on three each.
        std::vector<Vertex> polytope;
        for (int corner = 0; corner < 8; ++corner) {
            Vertex vertex;
            for (int axis = 0; axis < 3; ++axis) {
                const bool high = (corner >> axis) & 1;
                vertex.point[axis] = high ? hi[axis] : lo[axis];
                vertex.planes.push_back(2 * axis + (high ? 1 : 0));
            }
            polytope.push_back(vertex);
        }
        for (std::size_t other = 0; other < sites.size(); ++other) {
            if (other == site) {
                continue;
            }
            // Closer to `site` than to `other`: (other - site).x <= (|other|^2 - |site|^2) / 2.
            HalfSpace cut;
            for (int axis = 0; axis < 3; ++axis) {
                cut.normal[axis] = sites[other][axis] - sites[site][axis];
            }
            cut.offset = 0.5 * (dot(sites[other], sites[other]) - dot(sites[site], sites[site]));
            clip(polytope, cut, 6 + int(other), tolerance);
        }
        std::vector<Point3> cell;
        for (const Vertex& vertex : polytope) {
            cell.push_back(vertex.point);
        }
        cells.push_back(cell);
    }
    return cells;
}

Point3 haltonPoint(int index) {
    auto radicalInverse = [](int i, int base) {
        double result = 0, fraction = 1.0 / base;
        for (; i > 0; i /= base, fraction /= base) {
            result += fraction * (i % base);
        }
        return result;
    };
    return {radicalInverse(index, 2), radicalInverse(index, 3), radicalInverse(index, 5)};
}

}  // namespace kolize
