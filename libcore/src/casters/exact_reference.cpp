#include "impinge/casters/exact_reference.hpp"

#include "impinge/core/error.hpp"

#ifdef IMPINGE_HAVE_CGAL
#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>
#include <CGAL/Orthogonal_k_neighbor_search.h>
#include <CGAL/Search_traits_3.h>
#include <CGAL/Simple_cartesian.h>

#include <algorithm>
#include <iterator>
#include <vector>
#endif

namespace impinge {

#ifdef IMPINGE_HAVE_CGAL
namespace {
using K = CGAL::Simple_cartesian<double>;
using Triangle = K::Triangle_3;
using Iterator = std::vector<Triangle>::const_iterator;
using Primitive = CGAL::AABB_triangle_primitive<K, Iterator>;
using Tree = CGAL::AABB_tree<CGAL::AABB_traits<K, Primitive>>;
K::Point_3 pt(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }
}  // namespace

struct ExactReference::Impl {
  std::vector<Triangle> triangles;
  Tree tree;
};

bool have_exact_reference() { return true; }

ExactReference::ExactReference(const TriangleMesh& mesh) : impl_(std::make_unique<Impl>()) {
  validate_mesh(mesh);
  impl_->triangles.reserve(static_cast<std::size_t>(mesh.F.rows()));
  for (Eigen::Index f = 0; f < mesh.F.rows(); ++f) {
    const Triangle t(pt(mesh.V.row(mesh.F(f, 0)).transpose()), pt(mesh.V.row(mesh.F(f, 1)).transpose()),
                     pt(mesh.V.row(mesh.F(f, 2)).transpose()));
    if (!t.is_degenerate()) impl_->triangles.push_back(t);
  }
  impl_->tree.insert(impl_->triangles.begin(), impl_->triangles.end());
  impl_->tree.build();
  impl_->tree.accelerate_distance_queries();
}

std::optional<double> ExactReference::first_hit(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction) const {
  const K::Ray_3 ray(pt(origin), K::Vector_3(direction.x(), direction.y(), direction.z()));
  const auto hit = impl_->tree.first_intersection(ray);
  if (!hit) return std::nullopt;
  const K::Point_3* p = boost::get<K::Point_3>(&hit->first);
  if (p != nullptr) return std::sqrt(CGAL::squared_distance(*p, ray.source()));
  const K::Segment_3* s = boost::get<K::Segment_3>(&hit->first);  // ray in the triangle's plane
  if (s != nullptr)
    return std::sqrt(
        std::min(CGAL::squared_distance(s->source(), ray.source()), CGAL::squared_distance(s->target(), ray.source())));
  return std::nullopt;
}

std::vector<std::pair<double, double>> ExactReference::all_hits(const Eigen::Vector3d& origin,
                                                               const Eigen::Vector3d& direction) const {
  const K::Ray_3 ray(pt(origin), K::Vector_3(direction.x(), direction.y(), direction.z()));
  std::vector<Tree::Intersection_and_primitive_id<K::Ray_3>::Type> hits;
  impl_->tree.all_intersections(ray, std::back_inserter(hits));
  std::vector<std::pair<double, double>> out;
  for (const auto& h : hits) {
    const Triangle& t = *h.second;
    const K::Vector_3 n = CGAL::cross_product(t.vertex(1) - t.vertex(0), t.vertex(2) - t.vertex(0));
    const double cosine =
        (n.x() * direction.x() + n.y() * direction.y() + n.z() * direction.z()) / std::sqrt(n.squared_length());
    if (const K::Point_3* p = boost::get<K::Point_3>(&h.first)) {
      out.emplace_back(std::sqrt(CGAL::squared_distance(*p, ray.source())), cosine);
    } else if (const K::Segment_3* s = boost::get<K::Segment_3>(&h.first)) {
      out.emplace_back(std::sqrt(std::min(CGAL::squared_distance(s->source(), ray.source()),
                                          CGAL::squared_distance(s->target(), ray.source()))),
                       0.0);
    }
  }
  std::sort(out.begin(), out.end());
  return out;
}

double ExactReference::closest_distance(const Eigen::Vector3d& p) const {
  return std::sqrt(impl_->tree.squared_distance(pt(p)));
}

namespace {
using SearchTraits = CGAL::Search_traits_3<K>;
using Search = CGAL::Orthogonal_k_neighbor_search<SearchTraits>;
}  // namespace

struct PointCloudIndex::Impl {
  Search::Tree tree;
};

PointCloudIndex::PointCloudIndex(const std::vector<Eigen::Vector3d>& points) : impl_(std::make_unique<Impl>()) {
  require(!points.empty(), "point index: no points");
  for (const auto& p : points) impl_->tree.insert(pt(p));
  impl_->tree.build();
}

double PointCloudIndex::nearest_distance(const Eigen::Vector3d& q) const {
  Search search(impl_->tree, pt(q), 1);
  return std::sqrt(search.begin()->second);
}

#else
struct ExactReference::Impl {};
struct PointCloudIndex::Impl {};
PointCloudIndex::PointCloudIndex(const std::vector<Eigen::Vector3d>&) {
  throw Error("point index needs CGAL, which this build was configured without (install libcgal-dev)");
}
double PointCloudIndex::nearest_distance(const Eigen::Vector3d&) const { return 0; }
bool have_exact_reference() { return false; }
ExactReference::ExactReference(const TriangleMesh&) {
  throw Error("exact references need CGAL, which this build was configured without (install libcgal-dev)");
}
std::optional<double> ExactReference::first_hit(const Eigen::Vector3d&, const Eigen::Vector3d&) const {
  return std::nullopt;
}
double ExactReference::closest_distance(const Eigen::Vector3d&) const { return 0; }
std::vector<std::pair<double, double>> ExactReference::all_hits(const Eigen::Vector3d&, const Eigen::Vector3d&) const {
  return {};
}
#endif

PointCloudIndex::~PointCloudIndex() = default;
PointCloudIndex::PointCloudIndex(PointCloudIndex&&) noexcept = default;
PointCloudIndex& PointCloudIndex::operator=(PointCloudIndex&&) noexcept = default;
ExactReference::~ExactReference() = default;
ExactReference::ExactReference(ExactReference&&) noexcept = default;
ExactReference& ExactReference::operator=(ExactReference&&) noexcept = default;

}  // namespace impinge
