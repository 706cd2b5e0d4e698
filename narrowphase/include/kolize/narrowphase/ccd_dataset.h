#pragma once
/// Reader for the CCD benchmark of Wang et al. (ACM TOG 2021, "Sample-Queries" layout).
///
/// A data set folder holds `<scene>/<vertex-face|edge-edge>/*.csv`. Each CSV row is
/// `x_num,x_den,y_num,y_den,z_num,z_den,T`: one point with exact rational coordinates and
/// the ground truth T (1 = the primitives touch for some t in [0, 1]). Eight rows make one
/// query: the four points at t = 0, then the same four at t = 1, ordered as in
/// `VertexFaceQuery` / `EdgeEdgeQuery`.
#include "kolize/narrowphase/ccd.h"

#include <string>
#include <vector>

namespace kolize::ccd {

enum class QueryKind { kVertexFace, kEdgeEdge };

/// "vertex-face" or "edge-edge", the folder names of the data set.
const char* kindName(QueryKind kind);

/// One query with its ground truth. Both query kinds share the 4 + 4 point layout.
struct LabeledQuery {
    std::array<Vec3, 4> start;
    std::array<Vec3, 4> end;
    bool collides = false;
};

/// All queries of one scene and kind, e.g. ("erleben-spikes", kVertexFace).
struct QuerySet {
    std::string scene;
    QueryKind kind = QueryKind::kVertexFace;
    std::vector<LabeledQuery> queries;
};

/// Reads one CSV file. Numerators and denominators are integers of any size (read with
/// GMP, e.g. denominators 2^1074 of subnormal coordinates). Throws std::runtime_error,
/// naming the file and line, when a row is malformed, a denominator is not positive, a
/// coordinate is not exactly representable as a double, or the row count is not a multiple
/// of 8 -- the robust method's guarantee is about the exact input, so the reader refuses to
/// round silently.
std::vector<LabeledQuery> readQueryCsv(const std::string& path);

/// Writes queries in the same format, every coordinate exactly (denominators are powers of
/// two). Throws std::runtime_error when the file cannot be written or a coordinate is not
/// finite.
void writeQueryCsv(const std::string& path, const std::vector<LabeledQuery>& queries);

/// Reads every `<scene>/<kind>/*.csv` found under `root` (at any depth), one QuerySet per
/// scene and kind, in path order; the scene is the kind folder's parent relative to
/// `root`. Throws std::runtime_error if `root` holds no CSV.
std::vector<QuerySet> readQueryFolder(const std::string& root);

/// Runs the query as the given kind with the robust method.
inline CcdResult robustQuery(QueryKind kind, const LabeledQuery& q, const RobustSettings& s) {
    return kind == QueryKind::kVertexFace ? vertexFaceRobust({q.start, q.end}, s)
                                          : edgeEdgeRobust({q.start, q.end}, s);
}

/// Runs the query as the given kind with the thesis baseline.
inline CcdResult cubicQuery(QueryKind kind, const LabeledQuery& q, const CubicSettings& s) {
    return kind == QueryKind::kVertexFace ? vertexFaceCubic({q.start, q.end}, s)
                                          : edgeEdgeCubic({q.start, q.end}, s);
}

}  // namespace kolize::ccd
