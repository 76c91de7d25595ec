#include "partsim/assets/convex_decomposition.h"

#include <HACD/hacdHACD.h>

extern "C" {
#include <libqhull_r/qhull_ra.h>
}

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <numeric>
#include <random>
#include <set>
#include <string>
#include <tuple>

#include "partsim/assets/mesh.h"
#include "partsim/core/error.h"

namespace partsim {
namespace {

namespace fs = std::filesystem;
using Eigen::Vector3d;

// HACD normalises the mesh so that half its bounding-box diagonal spans 1000 units; lengths in
// metres are converted with this factor times 2 / diagonal
constexpr double kHacdScale = 1000.0;

std::string MeshName(const MeshData& mesh) {
  return mesh.source.empty() ? std::string("mesh") : "mesh " + mesh.source;
}

// The input with vertices welded and degenerate triangles dropped, in double precision.
struct Welded {
  std::vector<Vector3d> vertices;
  std::vector<Eigen::Vector3i> faces;
  Vector3d lo, hi;
  double diagonal = 0.0;
};

Welded Weld(const MeshData& mesh) {
  const std::string name = MeshName(mesh);
  if (mesh.faces.empty()) throw Error(name + ": has no triangles");
  const int nv = static_cast<int>(mesh.vertices.size());
  for (int i = 0; i < nv; ++i) {
    if (!mesh.vertices[i].allFinite()) {
      throw Error(name + ": vertex " + std::to_string(i) + " is not finite (NaN or infinity)");
    }
  }
  for (size_t i = 0; i < mesh.faces.size(); ++i) {
    const Eigen::Vector3i& f = mesh.faces[i];
    if (f.minCoeff() < 0 || f.maxCoeff() >= nv) {
      throw Error(name + ": face " + std::to_string(i) + " refers to a vertex out of range (" +
                  std::to_string(nv) + " vertices)");
    }
  }

  Welded w;
  w.lo = Vector3d::Constant(std::numeric_limits<double>::infinity());
  w.hi = -w.lo;
  for (const Eigen::Vector3i& f : mesh.faces) {
    for (int k = 0; k < 3; ++k) {
      const Vector3d v = mesh.vertices[f[k]].cast<double>();
      w.lo = w.lo.cwiseMin(v);
      w.hi = w.hi.cwiseMax(v);
    }
  }
  w.diagonal = (w.hi - w.lo).norm();
  if (!(w.diagonal > 0.0)) throw Error(name + ": has no volume (all vertices coincide)");

  // quantise positions to a grid of 1e-6 diagonal; the first vertex in a cell stands for it
  const double cell = 1e-6 * w.diagonal;
  std::map<std::tuple<long long, long long, long long>, int> cells;
  std::vector<int> id(nv, -1);
  for (const Eigen::Vector3i& f : mesh.faces) {
    for (int k = 0; k < 3; ++k) {
      if (id[f[k]] >= 0) continue;
      const Vector3d v = mesh.vertices[f[k]].cast<double>();
      auto key = std::make_tuple(std::llround(v.x() / cell), std::llround(v.y() / cell),
                                 std::llround(v.z() / cell));
      auto [it, fresh] = cells.emplace(key, static_cast<int>(w.vertices.size()));
      if (fresh) w.vertices.push_back(v);
      id[f[k]] = it->second;
    }
  }
  for (const Eigen::Vector3i& f : mesh.faces) {
    Eigen::Vector3i g(id[f[0]], id[f[1]], id[f[2]]);
    if (g[0] == g[1] || g[1] == g[2] || g[0] == g[2]) continue;
    w.faces.push_back(g);
  }
  if (w.faces.empty()) throw Error(name + ": has no volume (every triangle is degenerate)");
  return w;
}

double SignedVolume(const std::vector<Vector3d>& v, const std::vector<Eigen::Vector3i>& faces) {
  double six_v = 0.0;
  for (const Eigen::Vector3i& f : faces) six_v += v[f[0]].dot(v[f[1]].cross(v[f[2]]));
  return six_v / 6.0;
}

// --- convex hulls (qhull) ---

// Convex hull of points, or nullptr when they span no volume. With `max_vertices` (at least 4),
// qhull stops once its hull has that many vertices: the hull of a subset, each vertex added being
// the point farthest outside some facet of the hull so far.
std::shared_ptr<MeshData> HullOrNull(const std::vector<Vector3d>& points, int max_vertices = 0) {
  if (points.size() < 4) return nullptr;
  std::vector<double> coords;
  coords.reserve(points.size() * 3);
  for (const Vector3d& p : points) coords.insert(coords.end(), {p.x(), p.y(), p.z()});

  qhT qh_storage;
  qhT* qh = &qh_storage;
  qh_zero(qh, stderr);
  // "TA n": stop after adding n vertices to the initial simplex (4 vertices)
  std::string flags = "qhull Qs";
  if (max_vertices >= 4 && static_cast<size_t>(max_vertices) < points.size())
    flags += " TA" + std::to_string(max_vertices - 4);
  // errors (flat or too few points) come back as a non-zero code; keep qhull quiet
  FILE* quiet = fopen("/dev/null", "w");
  int code = qh_new_qhull(qh, 3, static_cast<int>(points.size()), coords.data(), False,
                          flags.data(), nullptr, quiet ? quiet : stderr);
  std::shared_ptr<MeshData> out;
  if (code == 0) {
    out = std::make_shared<MeshData>();
    std::map<int, int> vertex_index;  // qhull point id -> output vertex
    facetT* facet;
    FORALLfacets {
      // the facet's vertices in order around it (merged facets may have more than three)
      setT* ordered = qh_facet3vertex(qh, facet);
      std::vector<int> ring;
      vertexT *vertex, **vertexp;
      FOREACHvertex_(ordered) {
        int pid = qh_pointid(qh, vertex->point);
        auto [it, fresh] = vertex_index.emplace(pid, static_cast<int>(out->vertices.size()));
        if (fresh) out->vertices.push_back(points[pid].cast<float>());
        ring.push_back(it->second);
      }
      qh_settempfree(qh, &ordered);
      // orient the ring along the facet's outward normal, then fan it into triangles
      Vector3d n = Vector3d::Zero();
      for (size_t k = 1; k + 1 < ring.size(); ++k) {
        const Vector3d a = out->vertices[ring[0]].cast<double>();
        n += (out->vertices[ring[k]].cast<double>() - a)
                 .cross(out->vertices[ring[k + 1]].cast<double>() - a);
      }
      const Vector3d facet_normal(facet->normal[0], facet->normal[1], facet->normal[2]);
      if (n.dot(facet_normal) < 0) std::reverse(ring.begin(), ring.end());
      for (size_t k = 1; k + 1 < ring.size(); ++k) {
        out->faces.emplace_back(ring[0], ring[k], ring[k + 1]);
      }
    }
  }
  qh_freeqhull(qh, !qh_ALL);
  int curlong = 0, totlong = 0;
  qh_memfreeshort(qh, &curlong, &totlong);
  if (quiet) fclose(quiet);
  return out;
}

// --- HACD ---

struct HacdOutput {
  std::vector<std::vector<int>> clusters;          // triangle ids per cluster
  std::vector<std::vector<Vector3d>> hull_points;  // HACD's (simplified) hull per cluster
};

HacdOutput RunHacd(const Welded& w, double concavity_hacd, size_t min_clusters, double connect_hacd,
                   const ConvexDecompositionOptions& o, const std::string& name) {
  std::vector<HACD::Vec3<HACD::Real>> points;
  points.reserve(w.vertices.size());
  for (const Vector3d& v : w.vertices) points.emplace_back(v.x(), v.y(), v.z());
  std::vector<HACD::Vec3<long>> triangles;
  triangles.reserve(w.faces.size());
  for (const Eigen::Vector3i& f : w.faces) triangles.emplace_back(f[0], f[1], f[2]);

  HACD::HACD hacd;
  hacd.SetPoints(points.data());
  hacd.SetNPoints(points.size());
  hacd.SetTriangles(triangles.data());
  hacd.SetNTriangles(triangles.size());
  hacd.SetScaleFactor(kHacdScale);
  hacd.SetCompacityWeight(o.compacity_weight);
  hacd.SetVolumeWeight(o.volume_weight);
  hacd.SetConnectDist(connect_hacd);
  hacd.SetNClusters(min_clusters);
  hacd.SetNVerticesPerCH(o.max_hull_vertices > 0 ? o.max_hull_vertices : 1 << 20);
  hacd.SetConcavity(concavity_hacd);
  hacd.SetAddExtraDistPoints(o.add_extra_dist_points);
  hacd.SetAddFacesPoints(o.add_faces_points);
  hacd.SetAddNeighboursDistPoints(o.add_neighbours_dist_points);
  if (!hacd.Compute(false, false) || hacd.GetNClusters() == 0) {
    throw Error(name + ": HACD found no decomposition");
  }

  // clusters from the partition (ids renumbered in order of first triangle)
  HacdOutput out;
  const long* partition = hacd.GetPartition();
  std::map<long, int> index;
  std::vector<long> hacd_id;
  for (size_t t = 0; t < w.faces.size(); ++t) {
    auto [it, fresh] = index.emplace(partition[t], static_cast<int>(out.clusters.size()));
    if (fresh) {
      out.clusters.emplace_back();
      hacd_id.push_back(partition[t]);
    }
    out.clusters[it->second].push_back(static_cast<int>(t));
  }
  if (o.max_hull_vertices > 0) {
    for (long c : hacd_id) {
      std::vector<Vector3d> hull;
      if (c >= 0 && static_cast<size_t>(c) < hacd.GetNClusters()) {
        std::vector<HACD::Vec3<HACD::Real>> p(hacd.GetNPointsCH(c));
        std::vector<HACD::Vec3<long>> t(hacd.GetNTrianglesCH(c));
        if (!p.empty() && hacd.GetCH(c, p.data(), t.data())) {
          for (const auto& q : p) hull.emplace_back(q.X(), q.Y(), q.Z());
        }
      }
      out.hull_points.push_back(std::move(hull));
    }
  }
  return out;
}

// --- sampling the quality measures ---

struct Plane {
  Vector3d n;  // outward unit normal
  double d;    // n . x <= d inside
};

struct Piece {
  std::vector<Vector3d> v;
  std::vector<Eigen::Vector3i> f;
  std::vector<Plane> planes;
  Vector3d lo, hi;
};

Piece MakePiece(const MeshData& m) {
  Piece p;
  for (const Eigen::Vector3f& v : m.vertices) p.v.push_back(v.cast<double>());
  p.f = m.faces;
  p.lo = p.hi = p.v[0];
  for (const Vector3d& v : p.v) {
    p.lo = p.lo.cwiseMin(v);
    p.hi = p.hi.cwiseMax(v);
  }
  for (const Eigen::Vector3i& f : p.f) {
    Vector3d n = (p.v[f[1]] - p.v[f[0]]).cross(p.v[f[2]] - p.v[f[0]]);
    const double len = n.norm();
    if (len <= 0) continue;
    n /= len;
    p.planes.push_back({n, n.dot(p.v[f[0]])});
  }
  return p;
}

// Largest signed plane distance: <= 0 inside the piece; a lower bound on the distance outside.
double PlaneDistance(const Piece& p, const Vector3d& x) {
  double worst = -std::numeric_limits<double>::infinity();
  for (const Plane& pl : p.planes) worst = std::max(worst, pl.n.dot(x) - pl.d);
  return worst;
}

// Distance from x to triangle abc (Ericson, Real-Time Collision Detection 5.1.5).
double PointTriangleDistance(const Vector3d& x, const Vector3d& a, const Vector3d& b,
                             const Vector3d& c) {
  const Vector3d ab = b - a, ac = c - a, ap = x - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return ap.norm();
  const Vector3d bp = x - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return bp.norm();
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return (x - (a + ab * (d1 / (d1 - d3)))).norm();
  const Vector3d cp = x - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return cp.norm();
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return (x - (a + ac * (d2 / (d2 - d6)))).norm();
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
    return (x - (b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6))))).norm();
  }
  const double denom = 1.0 / (va + vb + vc);
  return (x - (a + ab * (vb * denom) + ac * (vc * denom))).norm();
}

// Distance from x to the nearest piece (0 inside one).
double DistanceToPieces(const std::vector<Piece>& pieces, const Vector3d& x) {
  // visit pieces by their plane bound, nearest first, and stop when the bound exceeds the best
  std::vector<std::pair<double, int>> order;
  for (size_t i = 0; i < pieces.size(); ++i) {
    const double bound = PlaneDistance(pieces[i], x);
    if (bound <= 0) return 0.0;
    order.emplace_back(bound, static_cast<int>(i));
  }
  std::sort(order.begin(), order.end());
  double best = std::numeric_limits<double>::infinity();
  for (const auto& [bound, i] : order) {
    if (bound >= best) break;
    const Piece& p = pieces[i];
    for (const Eigen::Vector3i& f : p.f) {
      best = std::min(best, PointTriangleDistance(x, p.v[f[0]], p.v[f[1]], p.v[f[2]]));
    }
  }
  return best;
}

bool InsideAnyPiece(const std::vector<Piece>& pieces, const Vector3d& x) {
  for (const Piece& p : pieces) {
    if ((x.array() < p.lo.array()).any() || (x.array() > p.hi.array()).any()) continue;
    if (PlaneDistance(p, x) <= 0) return true;
  }
  return false;
}

// Fills the surface measures: coverage and max_surface_distance.
void MeasureSurface(const Welded& w, const std::vector<Piece>& pieces,
                    const ConvexDecompositionOptions& o, ConvexDecompositionResult* r) {
  // area-weighted random points on the triangles
  std::vector<double> cumulative;
  double area = 0.0;
  for (const Eigen::Vector3i& f : w.faces) {
    area += 0.5 *
            (w.vertices[f[1]] - w.vertices[f[0]]).cross(w.vertices[f[2]] - w.vertices[f[0]]).norm();
    cumulative.push_back(area);
  }
  std::mt19937 rng(o.seed);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  int covered = 0;
  double worst = 0.0;
  const int n = std::max(1, o.surface_samples);
  for (int s = 0; s < n; ++s) {
    const double pick = uniform(rng) * area;
    const size_t t = std::min<size_t>(
        std::lower_bound(cumulative.begin(), cumulative.end(), pick) - cumulative.begin(),
        w.faces.size() - 1);
    double u = uniform(rng), v = uniform(rng);
    if (u + v > 1) {
      u = 1 - u;
      v = 1 - v;
    }
    const Eigen::Vector3i& f = w.faces[t];
    const Vector3d x = w.vertices[f[0]] + u * (w.vertices[f[1]] - w.vertices[f[0]]) +
                       v * (w.vertices[f[2]] - w.vertices[f[0]]);
    const double d = DistanceToPieces(pieces, x);
    worst = std::max(worst, d);
    if (d <= r->coverage_tolerance) ++covered;
  }
  r->coverage = static_cast<double>(covered) / n;
  r->max_surface_distance = worst;
}

// Fills the volume measures: hull_union_volume_estimate and excess. Stratified samples on a grid
// over the bounding box; inside-the-mesh by the parity of crossings along a vertical ray.
void MeasureVolume(const Welded& w, const std::vector<Piece>& pieces,
                   const ConvexDecompositionOptions& o, ConvexDecompositionResult* r) {
  const Vector3d size = (w.hi - w.lo).cwiseMax(1e-9 * w.diagonal);
  const double cell_side = std::cbrt(size.prod() / std::max(1000, o.volume_samples));
  Eigen::Vector3i cells;
  for (int k = 0; k < 3; ++k) {
    cells[k] = std::max(1, static_cast<int>(std::lround(size[k] / cell_side)));
  }
  const Vector3d step = size.cwiseQuotient(cells.cast<double>());
  const double cell_volume = step.prod();

  // triangles binned by the columns their xy bounding box overlaps
  std::vector<std::vector<int>> column_tris(static_cast<size_t>(cells.x()) * cells.y());
  for (size_t t = 0; t < w.faces.size(); ++t) {
    const Eigen::Vector3i& f = w.faces[t];
    Vector3d lo = w.vertices[f[0]], hi = lo;
    for (int k = 1; k < 3; ++k) {
      lo = lo.cwiseMin(w.vertices[f[k]]);
      hi = hi.cwiseMax(w.vertices[f[k]]);
    }
    const int i0 = std::clamp(static_cast<int>((lo.x() - w.lo.x()) / step.x()), 0, cells.x() - 1);
    const int i1 = std::clamp(static_cast<int>((hi.x() - w.lo.x()) / step.x()), 0, cells.x() - 1);
    const int j0 = std::clamp(static_cast<int>((lo.y() - w.lo.y()) / step.y()), 0, cells.y() - 1);
    const int j1 = std::clamp(static_cast<int>((hi.y() - w.lo.y()) / step.y()), 0, cells.y() - 1);
    for (int i = i0; i <= i1; ++i) {
      for (int j = j0; j <= j1; ++j) column_tris[i * cells.y() + j].push_back(static_cast<int>(t));
    }
  }

  std::mt19937 rng(o.seed + 1);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  long long in_union = 0, outside_mesh = 0;
  std::vector<double> crossings;
  for (int i = 0; i < cells.x(); ++i) {
    for (int j = 0; j < cells.y(); ++j) {
      // a random vertical line through this column, and where it crosses the surface
      const double x = w.lo.x() + (i + uniform(rng)) * step.x();
      const double y = w.lo.y() + (j + uniform(rng)) * step.y();
      crossings.clear();
      for (int t : column_tris[i * cells.y() + j]) {
        const Eigen::Vector3i& f = w.faces[t];
        const Vector3d &a = w.vertices[f[0]], &b = w.vertices[f[1]], &c = w.vertices[f[2]];
        // signed areas of the xy projections decide whether the line passes through
        auto edge = [x, y](const Vector3d& p, const Vector3d& q) {
          return (q.x() - p.x()) * (y - p.y()) - (q.y() - p.y()) * (x - p.x());
        };
        const double e0 = edge(a, b), e1 = edge(b, c), e2 = edge(c, a);
        const bool pos = e0 > 0 && e1 > 0 && e2 > 0, neg = e0 < 0 && e1 < 0 && e2 < 0;
        if (!pos && !neg) continue;
        const double sum = e0 + e1 + e2;
        crossings.push_back((e1 * a.z() + e2 * b.z() + e0 * c.z()) / sum);
      }
      std::sort(crossings.begin(), crossings.end());
      for (int k = 0; k < cells.z(); ++k) {
        const double z = w.lo.z() + (k + uniform(rng)) * step.z();
        if (!InsideAnyPiece(pieces, Vector3d(x, y, z))) continue;
        ++in_union;
        const size_t below =
            std::lower_bound(crossings.begin(), crossings.end(), z) - crossings.begin();
        if (below % 2 == 0) ++outside_mesh;
      }
    }
  }
  r->hull_union_volume_estimate = in_union * cell_volume;
  r->excess = outside_mesh * cell_volume / r->mesh_volume;
}

void CheckOption(bool ok, const std::string& what) {
  if (!ok) throw Error("ConvexDecompositionOptions: " + what);
}

}  // namespace

double MeshVolume(const MeshData& mesh) {
  double six_v = 0.0;
  const int nv = static_cast<int>(mesh.vertices.size());
  for (const Eigen::Vector3i& f : mesh.faces) {
    if (f.minCoeff() < 0 || f.maxCoeff() >= nv) continue;
    const Vector3d a = mesh.vertices[f[0]].cast<double>(), b = mesh.vertices[f[1]].cast<double>(),
                   c = mesh.vertices[f[2]].cast<double>();
    six_v += a.dot(b.cross(c));
  }
  return six_v / 6.0;
}

std::shared_ptr<MeshData> ConvexHull(const std::vector<Vector3d>& points, int max_vertices) {
  if (max_vertices != 0 && max_vertices < 4)
    throw Error("ConvexHull: max_vertices is " + std::to_string(max_vertices) +
                ", must be 0 (no limit) or at least 4");
  for (size_t i = 0; i < points.size(); ++i) {
    if (!points[i].allFinite()) {
      throw Error("ConvexHull: point " + std::to_string(i) + " is not finite");
    }
  }
  auto hull = HullOrNull(points, max_vertices);
  if (!hull) {
    throw Error("ConvexHull: the " + std::to_string(points.size()) +
                " points span no volume (fewer than 4, or all on one plane)");
  }
  return hull;
}

ConvexDecompositionResult DecomposeConvex(const MeshData& mesh,
                                          const ConvexDecompositionOptions& options) {
  const std::string name = MeshName(mesh);
  const ConvexDecompositionOptions& o = options;
  CheckOption(std::isfinite(o.concavity), "concavity must be finite");
  CheckOption(o.max_pieces >= 1, "max_pieces must be >= 1");
  CheckOption(o.min_pieces >= 1, "min_pieces must be >= 1");
  CheckOption(o.min_pieces <= o.max_pieces, "min_pieces must be <= max_pieces");
  CheckOption(o.max_hull_vertices == 0 || o.max_hull_vertices >= 4,
              "max_hull_vertices must be 0 (no limit) or >= 4");
  CheckOption(std::isfinite(o.coverage_tolerance), "coverage_tolerance must be finite");
  CheckOption(std::isfinite(o.connect_distance), "connect_distance must be finite");

  const Welded w = Weld(mesh);
  ConvexDecompositionResult r;
  r.diagonal = w.diagonal;
  r.mesh_volume = std::abs(SignedVolume(w.vertices, w.faces));
  if (r.mesh_volume <= 1e-9 * std::pow(w.diagonal, 3)) {
    throw Error(name + ": has no volume (a flat or open surface; a closed mesh is needed)");
  }
  r.concavity = o.concavity > 0 ? o.concavity : 0.01 * w.diagonal;
  r.coverage_tolerance = o.coverage_tolerance > 0 ? o.coverage_tolerance : 0.002 * w.diagonal;
  const double to_hacd = 2.0 * kHacdScale / w.diagonal;
  const double connect = o.connect_distance > 0 ? o.connect_distance : 0.015 * w.diagonal;

  // cluster with the concavity bound; too many clusters: merge down to max_pieces
  HacdOutput h = RunHacd(w, r.concavity * to_hacd, o.min_pieces, connect * to_hacd, o, name);
  if (static_cast<int>(h.clusters.size()) > o.max_pieces) {
    h = RunHacd(w, std::numeric_limits<double>::max(), o.max_pieces, connect * to_hacd, o, name);
  }

  // the points of each cluster: its vertices, or HACD's simplified hull
  const int nc = static_cast<int>(h.clusters.size());
  std::vector<std::vector<Vector3d>> points(nc);
  std::vector<std::set<int>> vertex_sets(nc);
  for (int c = 0; c < nc; ++c) {
    for (int t : h.clusters[c]) {
      for (int k = 0; k < 3; ++k) vertex_sets[c].insert(w.faces[t][k]);
    }
    if (!h.hull_points.empty() && h.hull_points[c].size() >= 4) {
      points[c] = h.hull_points[c];
    } else {
      for (int v : vertex_sets[c]) points[c].push_back(w.vertices[v]);
    }
  }

  // hulls; a flat cluster (no volume) joins the cluster whose hull it grows least (the two flat
  // sides of a thin plate join each other)
  std::vector<std::shared_ptr<MeshData>> hulls(nc);
  std::vector<bool> alive(nc, true);
  for (int c = 0; c < nc; ++c) hulls[c] = HullOrNull(points[c]);
  auto volume = [](const std::shared_ptr<MeshData>& m) { return m ? MeshVolume(*m) : 0.0; };
  for (bool changed = true; changed;) {
    changed = false;
    for (int c = 0; c < nc; ++c) {
      if (!alive[c] || hulls[c]) continue;
      int best = -1;
      double best_added = std::numeric_limits<double>::infinity();
      std::shared_ptr<MeshData> best_hull;
      for (int d = 0; d < nc; ++d) {
        if (d == c || !alive[d]) continue;
        std::vector<Vector3d> merged = points[d];
        merged.insert(merged.end(), points[c].begin(), points[c].end());
        std::shared_ptr<MeshData> hull = HullOrNull(merged);
        const double added = volume(hull) - volume(hulls[d]);
        if (added < best_added) {
          best = d;
          best_added = added;
          best_hull = hull;
        }
      }
      if (best < 0) throw Error(name + ": has no volume (its clusters are flat)");
      points[best].insert(points[best].end(), points[c].begin(), points[c].end());
      vertex_sets[best].insert(vertex_sets[c].begin(), vertex_sets[c].end());
      hulls[best] = best_hull;
      alive[c] = false;
      changed = true;
    }
  }
  for (int c = 0; c < nc; ++c) {
    if (!alive[c] || !hulls[c]) continue;
    hulls[c]->source = mesh.source;
    hulls[c]->name = (mesh.name.empty() ? std::string("piece") : mesh.name) + "_" +
                     std::to_string(r.pieces.size());
    r.pieces.push_back(hulls[c]);
  }

  // how well the pieces fit the input
  std::vector<Piece> pieces;
  for (const auto& p : r.pieces) pieces.push_back(MakePiece(*p));
  MeasureSurface(w, pieces, o, &r);
  MeasureVolume(w, pieces, o, &r);
  return r;
}

ConvexDecompositionResult DecomposeConvexFile(const std::string& path,
                                              const ConvexDecompositionOptions& options,
                                              const Eigen::Vector3d& scale) {
  std::shared_ptr<MeshData> mesh = LoadMergedMesh(path, scale);
  mesh->source = path;
  return DecomposeConvex(*mesh, options);
}

std::vector<std::string> WriteConvexPieces(const ConvexDecompositionResult& result,
                                           const std::string& dir, const std::string& basename) {
  if (basename.empty() || basename.find('/') != std::string::npos) {
    throw Error("WriteConvexPieces: basename '" + basename + "' must be a non-empty file name");
  }
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) throw Error("WriteConvexPieces: cannot create folder " + dir + ": " + ec.message());

  std::vector<std::string> written;
  std::vector<std::string> names;
  for (size_t k = 0; k < result.pieces.size(); ++k) {
    const MeshData& m = *result.pieces[k];
    const std::string file = basename + "_" + std::to_string(k) + ".obj";
    const std::string path = (fs::path(dir) / file).string();
    std::ofstream out(path);
    if (!out) throw Error("WriteConvexPieces: cannot write " + path);
    out.precision(9);
    out << "# convex piece " << k << " of " << result.pieces.size() << " (partsim)\n";
    out << "o " << basename << "_" << k << "\n";
    for (const Eigen::Vector3f& v : m.vertices) {
      out << "v " << v.x() << " " << v.y() << " " << v.z() << "\n";
    }
    for (const Eigen::Vector3i& f : m.faces) {
      out << "f " << f[0] + 1 << " " << f[1] + 1 << " " << f[2] + 1 << "\n";
    }
    if (!out) throw Error("WriteConvexPieces: cannot write " + path);
    written.push_back(path);
    names.push_back(file);
  }

  const std::string urdf = (fs::path(dir) / (basename + "_collision.urdf.xml")).string();
  std::ofstream out(urdf);
  if (!out) throw Error("WriteConvexPieces: cannot write " + urdf);
  out << "<!-- " << names.size() << " convex collision pieces of " << basename
      << " (partsim convex decomposition); paste inside a <link>. Mesh paths are relative to "
         "this folder. -->\n";
  for (size_t k = 0; k < names.size(); ++k) {
    out << "<collision name=\"" << basename << "_" << k << "\">\n"
        << "  <origin xyz=\"0 0 0\" rpy=\"0 0 0\"/>\n"
        << "  <geometry><mesh filename=\"" << names[k] << "\"/></geometry>\n"
        << "</collision>\n";
  }
  if (!out) throw Error("WriteConvexPieces: cannot write " + urdf);
  written.push_back(urdf);
  return written;
}

}  // namespace partsim
