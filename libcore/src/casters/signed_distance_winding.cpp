// The winding number of SignedDistanceQuery (Barill et al. 2018: fast winding numbers for soups), exact and by
// its hierarchy, which is built at its first use.
#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstring>
#include <limits>
#include <mutex>
#include <string>
#include <utility>

#include "casters/signed_distance_impl.hpp"
#include "core/box_order.hpp"
#include "impinge/core/error.hpp"

namespace impinge {

std::int32_t SignedDistanceQuery::Impl::build_node(std::int32_t begin, std::int32_t end) {
  const auto id = static_cast<std::int32_t>(nodes.size());
  nodes.emplace_back();
  Node n;
  n.begin = begin, n.end = end;
  double total = 0;
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (std::int32_t k = begin; k < end; ++k) {
    const auto t = static_cast<std::size_t>(order[static_cast<std::size_t>(k)]);
    const Eigen::Vector3d& av = area_vector[t];
    const Eigen::Vector3d& g = centroid[t];
    n.area += av;
    n.centre += av.norm() * g;
    total += av.norm();
    lo = lo.cwiseMin(g), hi = hi.cwiseMax(g);
  }
  n.centre /= total;
  double moment[3][3] = {};  // summed in plain accumulators (an Eigen temporary per term went through memory)
  for (std::int32_t k = begin; k < end; ++k) {
    const auto t = static_cast<std::size_t>(order[static_cast<std::size_t>(k)]);
    n.radius = std::max({n.radius, (a[t] - n.centre).squaredNorm(), (b[t] - n.centre).squaredNorm(),
                         (c[t] - n.centre).squaredNorm()});
    const Eigen::Vector3d d = centroid[t] - n.centre;
    const Eigen::Vector3d& av = area_vector[t];
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) moment[i][j] += d[i] * av[j];
  }
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) n.moment(i, j) = moment[i][j];
  n.radius = std::sqrt(n.radius);
  if (end - begin > 8) {
    int axis = 0;
    (hi - lo).maxCoeff(&axis);
    const std::int32_t mid = begin + (end - begin) / 2;
    std::nth_element(order.begin() + begin, order.begin() + mid, order.begin() + end, [&](std::int32_t x, std::int32_t y) {
      const auto i = static_cast<std::size_t>(x), j = static_cast<std::size_t>(y);
      return centroid[i][axis] < centroid[j][axis];
    });
    n.left = build_node(begin, mid);
    n.right = build_node(mid, end);
  }
  nodes[static_cast<std::size_t>(id)] = n;
  return id;
}

void SignedDistanceQuery::Impl::build_hierarchy() {
  const std::size_t k = a.size();
  order.resize(k);
  area_vector.resize(k), centroid.resize(k);
  for (std::size_t t = 0; t < k; ++t) {
    order[t] = static_cast<std::int32_t>(t);
    area_vector[t] = (b[t] - a[t]).cross(c[t] - a[t]) / 2;
    centroid[t] = (a[t] + b[t] + c[t]) / 3;
  }
  nodes.reserve(k / 2);
  build_node(0, static_cast<std::int32_t>(k));
  std::vector<Eigen::Vector3d>().swap(area_vector), std::vector<Eigen::Vector3d>().swap(centroid);
}

namespace {
/// Half the solid angle of triangle (A, B, C) seen from q (van Oosterom & Strackee 1983).
double half_solid_angle(const Eigen::Vector3d& q, const Eigen::Vector3d& A, const Eigen::Vector3d& B,
                        const Eigen::Vector3d& C) {
  const Eigen::Vector3d a = A - q, b = B - q, c = C - q;
  const double la = a.norm(), lb = b.norm(), lc = c.norm();
  const double det = a.dot(b.cross(c));
  const double div = la * lb * lc + a.dot(b) * lc + b.dot(c) * la + c.dot(a) * lb;
  return std::atan2(det, div);
}
constexpr double kDipoleBeta = 4;     // a cluster farther than this many of its radii away is a dipole
constexpr double kFastMargin = 0.1;   // the hierarchical sum decides when this far from 1/2
}  // namespace

double SignedDistanceQuery::winding_number(const Eigen::Vector3d& q) const {
  if (const SignedDistanceQuery* whole = impl_->whole_query()) return whole->winding_number(q);  // cropped
  const Impl& m = *impl_;
  double sum = 0;
  for (std::size_t t = 0; t < m.a.size(); ++t) sum += half_solid_angle(q, m.a[t], m.b[t], m.c[t]);
  return m.orientation * sum / (2 * M_PI);
}

double SignedDistanceQuery::winding_number_fast(const Eigen::Vector3d& q) const {
  if (const SignedDistanceQuery* whole = impl_->whole_query()) return whole->winding_number_fast(q);  // cropped
  std::call_once(impl_->hierarchy_built, [this] { impl_->build_hierarchy(); });
  const Impl& m = *impl_;
  double sum = 0;
  std::int32_t stack[128];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const Impl::Node& n = m.nodes[static_cast<std::size_t>(stack[--top])];
    const Eigen::Vector3d d = n.centre - q;
    const double dist = d.norm();
    if (dist > kDipoleBeta * n.radius) {
      // Half the solid angle of the cluster's dipoles, to second order about its centre: with
      // F(x) = x / |x|^3 and J = dF/dx = I / |d|^3 - 3 d d^T / |d|^5, sum_t a_t . F(d + e_t) ~
      // N . F(d) + tr(J M) (Barill et al. 2018, eq. 11-12).
      const double d2 = dist * dist, d3 = d2 * dist;
      sum += (n.area.dot(d) / d3 + n.moment.trace() / d3 - 3 * d.dot(n.moment * d) / (d3 * d2)) / 2;
    } else if (n.left < 0 || top + 2 > 128) {
      for (std::int32_t k = n.begin; k < n.end; ++k) {
        const auto t = static_cast<std::size_t>(m.order[static_cast<std::size_t>(k)]);
        sum += half_solid_angle(q, m.a[t], m.b[t], m.c[t]);
      }
    } else {
      stack[top++] = n.left;
      stack[top++] = n.right;
    }
  }
  return m.orientation * sum / (2 * M_PI);
}

double SignedDistanceQuery::winding_number_decided(const Eigen::Vector3d& q) const {
  if (const SignedDistanceQuery* whole = impl_->whole_query()) return whole->winding_number_decided(q);  // cropped
  const double fast = winding_number_fast(q);
  return std::abs(fast - 0.5) > kFastMargin ? fast : winding_number(q);
}

bool SignedDistanceQuery::inside_by_winding_number(const Eigen::Vector3d& q) const {
  if (const SignedDistanceQuery* whole = impl_->whole_query()) return whole->inside_by_winding_number(q);  // cropped
  const double fast = winding_number_fast(q);
  if (std::abs(fast - 0.5) > kFastMargin) return fast > 0.5;
  return winding_number(q) >= 0.5;
}

}  // namespace impinge
