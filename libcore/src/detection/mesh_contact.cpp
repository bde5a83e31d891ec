#include "impinge/detection/mesh_contact.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>
#include <string>
#include <utility>

#include "impinge/core/error.hpp"

namespace impinge {
using Eigen::Vector3d;

namespace {
// The slack of the faces' sphere test (MeshContact::walk), mm: far above the rounding of either distance.
constexpr double kSphereMarginMm = 1e-6;

// The closest point of triangle (a, b, c) to p (Ericson 2005, sec. 5.1.5: Voronoi regions).
Vector3d closest_on_triangle(const Vector3d& p, const Vector3d& a, const Vector3d& b, const Vector3d& c) {
  const Vector3d ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return a;
  const Vector3d bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + (d1 / (d1 - d3)) * ab;
  const Vector3d cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + (d2 / (d2 - d6)) * ac;
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) return b + ((d4 - d3) / ((d4 - d3) + (d5 - d6))) * (c - b);
  const double denom = va + vb + vc;
  if (!(denom > 0)) {  // degenerate (zero area): the closest of its edges
    auto on_segment = [&p](const Vector3d& s, const Vector3d& e) {
      const Vector3d d = e - s;
      const double l2 = d.squaredNorm();
      return l2 > 0 ? Vector3d(s + std::clamp((p - s).dot(d) / l2, 0.0, 1.0) * d) : s;
    };
    const std::array<Vector3d, 3> q{on_segment(a, b), on_segment(b, c), on_segment(c, a)};
    return *std::min_element(q.begin(), q.end(),
                             [&p](const Vector3d& x, const Vector3d& y) { return (x - p).squaredNorm() < (y - p).squaredNorm(); });
  }
  return a + ab * (vb / denom) + ac * (vc / denom);
}

// The closest points c1 on segment [p1, q1] and c2 on [p2, q2] (Ericson 2005, sec. 5.1.9).
void closest_segments(const Vector3d& p1, const Vector3d& q1, const Vector3d& p2, const Vector3d& q2, Vector3d& c1,
                      Vector3d& c2) {
  const Vector3d d1 = q1 - p1, d2 = q2 - p2, r = p1 - p2;
  const double a = d1.squaredNorm(), e = d2.squaredNorm(), f = d2.dot(r);
  double s = 0, t = 0;
  if (a <= 0 && e <= 0) {
    c1 = p1, c2 = p2;
    return;
  }
  if (a <= 0) {
    t = std::clamp(f / e, 0.0, 1.0);
  } else {
    const double c = d1.dot(r);
    if (e <= 0) {
      s = std::clamp(-c / a, 0.0, 1.0);
    } else {
      const double b = d1.dot(d2), denom = a * e - b * b;
      s = denom > 0 ? std::clamp((b * f - c * e) / denom, 0.0, 1.0) : 0.0;
      t = (b * s + f) / e;
      if (t < 0) {
        t = 0, s = std::clamp(-c / a, 0.0, 1.0);
      } else if (t > 1) {
        t = 1, s = std::clamp((b - c) / a, 0.0, 1.0);
      }
    }
  }
  c1 = p1 + d1 * s, c2 = p2 + d2 * t;
}

// Whether segment [p, q] meets triangle (a, b, c) where it crosses the triangle's plane (endpoints on
// opposite sides or on it); the point in x. A segment lying in the plane is left to the edge tests.
bool segment_crosses(const Vector3d& p, const Vector3d& q, const Vector3d& a, const Vector3d& b, const Vector3d& c,
                     Vector3d& x) {
  const Vector3d n = (b - a).cross(c - a);
  const double sp = n.dot(p - a), sq = n.dot(q - a);
  if ((sp > 0 && sq > 0) || (sp < 0 && sq < 0) || sp == sq) return false;
  x = p + (sp / (sp - sq)) * (q - p);
  // Inside (boundary included): the three edge cross products agree with the normal.
  return n.dot((b - a).cross(x - a)) >= 0 && n.dot((c - b).cross(x - b)) >= 0 && n.dot((a - c).cross(x - c)) >= 0;
}
// Whether triangles a and b (unit normals na, nb; zero for no area) lie farther apart than `bound` (>= 0) by a
// plane: every corner of one farther than `bound` from the other's plane on one side. Every point of the one
// is then that far from the plane (the corners' convex hull), which holds the other.
bool planes_apart(const Vector3d a[3], const Vector3d& na, const Vector3d b[3], const Vector3d& nb, double bound) {
  auto beyond = [bound](const Vector3d p[3], const Vector3d& n, const Vector3d& on) {
    const double s0 = n.dot(p[0] - on), s1 = n.dot(p[1] - on), s2 = n.dot(p[2] - on);
    return std::min({s0, s1, s2}) > bound || std::max({s0, s1, s2}) < -bound;
  };
  return beyond(b, na, a[0]) || beyond(a, nb, b[0]);
}
// A lower bound of the distance between box A (a_lo, a_hi; posed by R, t; Rabs = |R|, Rt = R^T, back = -R^T t)
// and box B: A's sphere against B's box, and the two boxes apart along B's axes (A's box posed, within its
// axis-aligned hull) or along A's (B's carried back), less a rounding margin.
double boxes_apart(const Eigen::Matrix3d& R, const Eigen::Matrix3d& Rabs, const Eigen::Matrix3d& Rt, const Vector3d& t,
                   const Vector3d& back, const Vector3d& a_lo, const Vector3d& a_hi, const Vector3d& b_lo,
                   const Vector3d& b_hi) {
  const Vector3d ha = 0.5 * (a_hi - a_lo), hb = 0.5 * (b_hi - b_lo), ca = 0.5 * (a_lo + a_hi), cb = 0.5 * (b_lo + b_hi);
  const Vector3d c = R * ca + t;
  const double sphere = (c - c.cwiseMax(b_lo).cwiseMin(b_hi)).norm() - ha.norm();
  const double in_b = ((c - cb).cwiseAbs() - Rabs * ha - hb).cwiseMax(0.0).norm();
  const double in_a = ((Rt * cb + back - ca).cwiseAbs() - Rabs.transpose() * hb - ha).cwiseMax(0.0).norm();
  return std::max(sphere, std::max(in_b, in_a)) - kSphereMarginMm;
}
}  // namespace

double triangle_distance(const Vector3d a[3], const Vector3d b[3], Vector3d& pa, Vector3d& pb) {
  Vector3d x;
  for (int i = 0; i < 3; ++i) {
    if (segment_crosses(a[i], a[(i + 1) % 3], b[0], b[1], b[2], x) ||
        segment_crosses(b[i], b[(i + 1) % 3], a[0], a[1], a[2], x)) {
      pa = pb = x;
      return 0;
    }
  }
  double best = std::numeric_limits<double>::infinity();
  auto take = [&](const Vector3d& u, const Vector3d& v) {
    const double d = (u - v).squaredNorm();
    if (d < best) best = d, pa = u, pb = v;
  };
  Vector3d c1, c2;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      closest_segments(a[i], a[(i + 1) % 3], b[j], b[(j + 1) % 3], c1, c2);
      take(c1, c2);
    }
  for (int i = 0; i < 3; ++i) {
    take(a[i], closest_on_triangle(a[i], b[0], b[1], b[2]));
    take(closest_on_triangle(b[i], a[0], a[1], a[2]), b[i]);
  }
  return std::sqrt(best);
}

MeshContact::Tree MeshContact::build(const Vertices& v, const Faces& f) {
  Tree tree;
  const auto m = static_cast<std::int32_t>(f.rows());
  tree.order.resize(static_cast<std::size_t>(m));
  std::iota(tree.order.begin(), tree.order.end(), 0);
  std::vector<Vector3d> centroid(static_cast<std::size_t>(m));
  tree.spheres.resize(static_cast<std::size_t>(m));
  for (std::int32_t k = 0; k < m; ++k) {
    const Vector3d c = (v.row(f(k, 0)) + v.row(f(k, 1)) + v.row(f(k, 2))).transpose() / 3.0;
    double r = 0;
    for (int j = 0; j < 3; ++j) r = std::max(r, (v.row(f(k, j)).transpose() - c).norm());
    centroid[static_cast<std::size_t>(k)] = c;
    tree.spheres[static_cast<std::size_t>(k)] = Eigen::Vector4d(c.x(), c.y(), c.z(), r);
    const Vector3d n = (v.row(f(k, 1)) - v.row(f(k, 0))).transpose().cross((v.row(f(k, 2)) - v.row(f(k, 0))).transpose());
    const double len = n.norm();
    tree.normals.push_back(len > 0 ? Vector3d(n / len) : Vector3d::Zero());
  }
  if (m == 0) return tree;
  struct Span {
    std::int32_t node, first, count;
  };
  tree.nodes.emplace_back();
  std::vector<Span> todo{{0, 0, m}};
  while (!todo.empty()) {
    const Span s = todo.back();
    todo.pop_back();
    Node n;
    n.lo = Vector3d::Constant(std::numeric_limits<double>::infinity()), n.hi = -n.lo;
    Vector3d clo = n.lo, chi = n.hi;
    for (std::int32_t k = s.first; k < s.first + s.count; ++k) {
      const std::int32_t face = tree.order[static_cast<std::size_t>(k)];
      for (int c = 0; c < 3; ++c) {
        const Vector3d p = v.row(f(face, c)).transpose();
        n.lo = n.lo.cwiseMin(p), n.hi = n.hi.cwiseMax(p);
      }
      clo = clo.cwiseMin(centroid[static_cast<std::size_t>(face)]), chi = chi.cwiseMax(centroid[static_cast<std::size_t>(face)]);
    }
    n.centre = 0.5 * (n.lo + n.hi), n.radius = 0.5 * (n.hi - n.lo).norm();
    n.first = s.first, n.count = s.count;
    if (s.count > 4) {  // split at the median centroid along the longest axis of the centroids
      Eigen::Index axis;
      (chi - clo).maxCoeff(&axis);
      const auto begin = tree.order.begin() + s.first, mid = begin + s.count / 2, end = begin + s.count;
      std::nth_element(begin, mid, end, [&](std::int32_t x, std::int32_t y) {
        return centroid[static_cast<std::size_t>(x)][axis] < centroid[static_cast<std::size_t>(y)][axis];
      });
      n.left = static_cast<std::int32_t>(tree.nodes.size());
      n.right = n.left + 1;
      tree.nodes.emplace_back(), tree.nodes.emplace_back();
      todo.push_back({n.left, s.first, s.count / 2});
      todo.push_back({n.right, s.first + s.count / 2, s.count - s.count / 2});
    }
    tree.nodes[static_cast<std::size_t>(s.node)] = n;
  }
  return tree;
}

void MeshContact::mark(Tree& tree, const std::vector<std::uint8_t>& counted, const Vertices& v, const Faces& f) {
  // Children are stored after their parents: from the back, a parent holds a counted face when a child does,
  // and the box of its counted faces is its children's.
  for (auto k = tree.nodes.size(); k-- > 0;) {
    Node& n = tree.nodes[k];
    n.counted_lo = Vector3d::Constant(std::numeric_limits<double>::infinity()), n.counted_hi = -n.counted_lo;
    if (n.left < 0) {
      for (std::int32_t j = n.first; j < n.first + n.count; ++j) {
        const std::int32_t face = tree.order[static_cast<std::size_t>(j)];
        if (counted[static_cast<std::size_t>(face)] == 0) continue;
        for (int c = 0; c < 3; ++c) {
          const Vector3d p = v.row(f(face, c)).transpose();
          n.counted_lo = n.counted_lo.cwiseMin(p), n.counted_hi = n.counted_hi.cwiseMax(p);
        }
      }
    } else {
      for (const std::int32_t child : {n.left, n.right}) {
        const Node& c = tree.nodes[static_cast<std::size_t>(child)];
        n.counted_lo = n.counted_lo.cwiseMin(c.counted_lo), n.counted_hi = n.counted_hi.cwiseMax(c.counted_hi);
      }
    }
    n.counted = (n.counted_lo.array() <= n.counted_hi.array()).all();
  }
}

MeshContact::MeshContact(const Vertices& a, const Faces& fa, const Vertices& b, const Faces& fb,
                         std::vector<std::uint8_t> a_counted, std::vector<std::uint8_t> b_counted)
    : a_(a), b_(b), fa_(fa), fb_(fb) {
  auto check_faces = [](const Vertices& v, const Faces& f, const char* which) {
    require(f.size() == 0 || (f.minCoeff() >= 0 && f.maxCoeff() < v.rows()),
            std::string("mesh contact: a face of mesh ") + which + " names a vertex out of range");
  };
  check_faces(a_, fa_, "A");
  check_faces(b_, fb_, "B");
  ta_ = build(a_, fa_);
  tb_ = build(b_, fb_);
  set_counted(std::move(a_counted), std::move(b_counted));
}

void MeshContact::set_counted(std::vector<std::uint8_t> a_counted, std::vector<std::uint8_t> b_counted) {
  if (a_counted.empty()) a_counted.assign(static_cast<std::size_t>(fa_.rows()), 1);
  if (b_counted.empty()) b_counted.assign(static_cast<std::size_t>(fb_.rows()), 1);
  require(a_counted.size() == static_cast<std::size_t>(fa_.rows()) && b_counted.size() == static_cast<std::size_t>(fb_.rows()),
          "mesh contact: a counted-face mask's length is not the mesh's face count");
  a_counted_ = std::move(a_counted), b_counted_ = std::move(b_counted);
  mark(ta_, a_counted_, a_, fa_);
  mark(tb_, b_counted_, b_, fb_);
}

// Both trees together: visit(face_a, face_b, posed corners of A's face, B's corners) for every counted pair
// whose bounds come within `bound` (which visit may lower; a visit returning true ends the walk).
template <typename Visit>
void MeshContact::walk(const Eigen::Matrix3d& R, const Eigen::Vector3d& t, const Query& q, double& bound,
                       Visit visit) const {
  if (ta_.nodes.empty() || tb_.nodes.empty()) return;
  // A lower bound of the distance between the counted pairs of A's node (posed) and B's: a counted face of
  // either against any face of the other (boxes; none counted: +inf).
  const Eigen::Matrix3d Rabs = R.cwiseAbs(), Rt = R.transpose();
  const Vector3d back = -(Rt * t);
  auto apart = [&](const Node& na, const Node& nb) {
    const double far = std::numeric_limits<double>::infinity();
    return std::min(na.counted ? boxes_apart(R, Rabs, Rt, t, back, na.counted_lo, na.counted_hi, nb.lo, nb.hi) : far,
                    nb.counted ? boxes_apart(R, Rabs, Rt, t, back, na.lo, na.hi, nb.counted_lo, nb.counted_hi) : far);
  };
  std::vector<std::pair<std::int32_t, std::int32_t>> stack{{0, 0}};
  Vector3d pa[3], pb[3];
  while (!stack.empty()) {
    const auto [ia, ib] = stack.back();
    stack.pop_back();
    const Node& na = ta_.nodes[static_cast<std::size_t>(ia)];
    const Node& nb = tb_.nodes[static_cast<std::size_t>(ib)];
    if (!(na.counted || nb.counted) || apart(na, nb) > bound) continue;
    if (na.left < 0 && nb.left < 0) {
      for (std::int32_t i = na.first; i < na.first + na.count; ++i) {
        const std::int32_t fa = ta_.order[static_cast<std::size_t>(i)];
        const bool ca = a_counted_[static_cast<std::size_t>(fa)] != 0;
        for (int c = 0; c < 3; ++c) pa[c] = R * a_.row(fa_(fa, c)).transpose() + t;
        const Eigen::Vector4d& sa = ta_.spheres[static_cast<std::size_t>(fa)];
        const Vector3d ca_posed = R * sa.head<3>() + t, na_posed = R * ta_.normals[static_cast<std::size_t>(fa)];
        for (std::int32_t j = nb.first; j < nb.first + nb.count; ++j) {
          const std::int32_t fb = tb_.order[static_cast<std::size_t>(j)];
          if (!ca && !(b_counted_[static_cast<std::size_t>(fb)] && (!q.b_counts_now || q.b_counts_now(fb)))) continue;
          // The faces' spheres apart by more than the bound (with a rounding margin): so are the faces, and a
          // pair farther than the bound changes no answer.
          const Eigen::Vector4d& sb = tb_.spheres[static_cast<std::size_t>(fb)];
          if ((ca_posed - sb.head<3>()).norm() - sa.w() - sb.w() > bound + kSphereMarginMm) continue;
          for (int c = 0; c < 3; ++c) pb[c] = b_.row(fb_(fb, c)).transpose();
          if (planes_apart(pa, na_posed, pb, tb_.normals[static_cast<std::size_t>(fb)], bound + kSphereMarginMm)) continue;
          if (visit(fa, fb, pa, pb)) return;
        }
      }
      continue;
    }
    // Split the larger node (a leaf is never split); the nearer child pair is walked first.
    const bool split_a = nb.left < 0 || (na.left >= 0 && na.radius >= nb.radius);
    std::pair<std::int32_t, std::int32_t> x{ia, ib}, y{ia, ib};
    if (split_a) x.first = na.left, y.first = na.right;
    else x.second = nb.left, y.second = nb.right;
    const Node& xa = ta_.nodes[static_cast<std::size_t>(x.first)], &xb = tb_.nodes[static_cast<std::size_t>(x.second)];
    const Node& ya = ta_.nodes[static_cast<std::size_t>(y.first)], &yb = tb_.nodes[static_cast<std::size_t>(y.second)];
    if (apart(xa, xb) <= apart(ya, yb)) std::swap(x, y);
    stack.push_back(x), stack.push_back(y);
  }
}

MeshContact::Closest MeshContact::least(const Eigen::Matrix3d& R, const Eigen::Vector3d& t, const Query& q) const {
  Closest out;
  double bound = q.reach;
  Vector3d on_a, on_b;
  // Ties broken by the midpoint's coordinates (lexicographic): the same pair whatever the order.
  auto before = [&](double d) {
    if (d != out.distance) return d < out.distance;
    const Vector3d m = on_a + on_b, n = out.on_a + out.on_b;
    return std::lexicographical_compare(m.data(), m.data() + 3, n.data(), n.data() + 3);
  };
  walk(R, t, q, bound, [&](std::int32_t fa, std::int32_t fb, const Vector3d* pa, const Vector3d* pb) {
    const double d = triangle_distance(pa, pb, on_a, on_b);
    if (d > bound || !before(d)) return false;
    if (a_counted_[static_cast<std::size_t>(fa)] == 2 && q.pair_counts && !q.pair_counts(fa, on_a, on_b)) return false;
    out = {d, fa, fb, on_a, on_b};
    bound = d;
    return q.first;
  });
  return out;
}

std::vector<std::pair<std::int64_t, std::int64_t>> MeshContact::pairs_within(const Eigen::Matrix3d& R,
                                                                            const Eigen::Vector3d& t, double reach,
                                                                            const Query& q) const {
  std::vector<std::pair<std::int64_t, std::int64_t>> out;
  double bound = reach;
  Vector3d on_a, on_b;
  walk(R, t, q, bound, [&](std::int32_t fa, std::int32_t fb, const Vector3d* pa, const Vector3d* pb) {
    if (triangle_distance(pa, pb, on_a, on_b) <= reach &&
        !(a_counted_[static_cast<std::size_t>(fa)] == 2 && q.pair_counts && !q.pair_counts(fa, on_a, on_b)))
      out.emplace_back(fa, fb);
    return false;
  });
  return out;
}

}  // namespace impinge
