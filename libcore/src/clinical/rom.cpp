#include "impinge/clinical/rom.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <memory>
#include <optional>

#include "clinical/rom_gap_scanner.hpp"
#include "impinge/core/error.hpp"
#include "impinge/core/interrupt.hpp"

namespace impinge {
using namespace rom_detail;

RomContacts parse_rom_contacts(const std::string& text, const std::string& context) {
  return parse_enum(kRomContactsNames, text, context);
}

const char* to_string(RomContacts contacts) {
  return enum_name(kRomContactsNames, contacts);
}

const char* to_string(RomMetric metric) { return enum_name(kRomMetricNames, metric); }

RomMetric parse_rom_metric(const std::string& text, const std::string& context) {
  return parse_enum(kRomMetricNames, text, context);
}

const char* to_string(ImpingementSite site) {
  switch (site) {
    case ImpingementSite::intra_articular: return "intra_articular";
    case ImpingementSite::extra_articular: return "extra_articular";
    case ImpingementSite::none: break;
  }
  return "";
}

const char* to_string(RomMapStatus status) {
  switch (status) {
    case RomMapStatus::limited: return "limited";
    case RomMapStatus::contact_at_zero: return "contact_at_zero";
    case RomMapStatus::free: break;
  }
  return "free";
}

const char* to_string(RomLimitStatus status) {
  switch (status) {
    case RomLimitStatus::limited: return "limited";
    case RomLimitStatus::contact_at_start: return "contact_at_start";
    case RomLimitStatus::not_reachable: return "not_reachable";
    case RomLimitStatus::free: break;
  }
  return "free";
}

std::vector<StandardMotion> standard_motions() {
  return {
      {"flexion", [](double t) { return PoseAngles{t, 0, 0}; }},
      {"extension", [](double t) { return PoseAngles{-t, 0, 0}; }},
      {"abduction", [](double t) { return PoseAngles{0, -t, 0}; }},
      {"adduction", [](double t) { return PoseAngles{0, t, 0}; }},
      {"internal_rotation", [](double t) { return PoseAngles{0, 0, t}; }},
      {"external_rotation", [](double t) { return PoseAngles{0, 0, -t}; }},
      {"internal_rotation_90_flexion", [](double t) { return PoseAngles{90, 0, t}; }, PoseAngles{90, 0, 0}},
      {"external_rotation_90_flexion", [](double t) { return PoseAngles{90, 0, -t}; }, PoseAngles{90, 0, 0}},
      {"fadir", [](double t) { return PoseAngles{90, 10, t}; }, PoseAngles{90, 10, 0}},
  };
}

RomBaseline rom_baseline(const HipJoint& hip, const Eigen::Matrix3d& R, const RomOptions& o) {
  check(o);
  check_metric(hip.joint(), o);
  require(hip.joint().options().layers == 0 || hip.joint().options().layered_maps,
          "ROM search: the joint was set up without its layered maps (query strategy 'direct', for a few poses); ROM "
          "searches need them: set it up with query strategy 'maps' (or 'auto')");
  PoseResult r;
  hip.joint().detect(R, hip.joint_translation(R), r);
  RomBaseline b;
  // The metric's values: the radial gaps, or the distances (NaN beyond the reach: not within the threshold).
  const bool by_distance = o.metric == RomMetric::distance;
  const std::vector<float>& ball_values = by_distance ? r.ball_gaps.distance_mm : r.ball_gaps.gap_mm;
  const std::vector<float>& socket_values = by_distance ? r.socket_gaps.distance_mm : r.socket_gaps.gap_mm;
  b.skip_ball.resize(r.ball_gaps.gap_mm.size());
  b.skip_socket.resize(r.socket_gaps.gap_mm.size());
  for (std::size_t i = 0; i < b.skip_ball.size(); ++i) b.skip_ball[i] = ball_values[i] <= o.threshold_mm;
  for (std::size_t i = 0; i < b.skip_socket.size(); ++i) b.skip_socket[i] = socket_values[i] <= o.threshold_mm;
  for (auto s : b.skip_ball) b.excluded_vertices += s;
  for (auto s : b.skip_socket) b.excluded_vertices += s;
  // The femoral head's joint surface: left out of impingement searches, the only one counted where the joint
  // space closes. The pelvis' contacts are classed at each pose by the scanner: those that meet the head up to
  // its head-neck junction are articular (RomBaseline::meets_head), wherever on the acetabulum they lie; the
  // lunate surface meeting the neck or a cam is not (issue 81), so it is not left out as a whole.
  const std::vector<std::uint8_t> skip_ball_pre = b.skip_ball;  // the exact test's: before any articular class
  if (const auto& z = hip.articular(); z && o.contacts != RomContacts::all) {
    const bool keep_articular = o.contacts == RomContacts::articular;
    for (std::size_t i = 0; i < b.skip_ball.size(); ++i)
      if (!b.skip_ball[i] && ((z->femur[i] != 0) != keep_articular)) b.skip_ball[i] = 1, ++b.articular_vertices;
    b.head_zone = hip.head_zone_joint();
    b.contacts = o.contacts;
  }
  if (const auto& z = hip.articular())
    for (std::size_t i = 0; i < z->pelvis.size(); ++i)
      if (z->pelvis[i] && std::isfinite(socket_values[i])) b.joint_space_min_mm = std::fmin(b.joint_space_min_mm, socket_values[i]);
  b.min_gap_mm = by_distance ? std::fmin(r.ball.min_distance_mm, r.socket.min_distance_mm)
                             : std::fmin(r.ball.min_gap_mm, r.socket.min_gap_mm);
  if (o.use_bounds && screened_or_radial(o))
    b.bounds = std::make_shared<const RomSearchBounds>(hip.joint(), scan_cut_of(o), &b.skip_ball, &b.skip_socket);
  // The exact test's meshes, whenever it applies at depth 0 (the first contact is always searched).
  if (exact_at(o, o.threshold_mm)) b.contact = baseline_contact(hip.joint(), b, skip_ball_pre, R, hip.joint_translation(R), o.threshold_mm);
  return b;
}

namespace {
// The first touch of a search at depth 0 (RomLimit::first_contact_deg): its limit, 0 with contact at the
// start, NaN when free; NaN at a depth > 0 (a search of its own gives it: with_first_contact).
double first_contact_of(const RomLimit& l, const RomOptions& o) {
  if (o.contact_depth_mm > 0 || l.status == RomLimitStatus::free) return std::numeric_limits<double>::quiet_NaN();
  return l.contact_at_start ? 0.0 : l.limit_deg;
}

// Where the limit's contact lies and what it is, from the least `l` at the pose (R, t): the exact contact
// point (Least::point) or the vertex, in the working frame, its site, class and clock hours.
void describe_contact(RomLimit& out, const HipJoint& hip, const Least& l, const Eigen::Matrix3d& R,
                      const Eigen::Vector3d& t, const RomOptions& o) {
  const Joint& joint = hip.joint();
  out.limited_by_ball = l.ball;
  // The contact point in the joint frame (the pelvis does not move): the exact one, or the vertex, posed.
  const Eigen::Vector3d p_joint =
      std::isfinite(l.point.x()) ? l.point
      : l.ball ? Eigen::Vector3d(R * joint.ball().relative.row(static_cast<Eigen::Index>(l.vertex)).transpose() + t)
               : Eigen::Vector3d(joint.socket().relative.row(static_cast<Eigen::Index>(l.vertex)).transpose());
  out.contact_mm = hip.to_working(p_joint);
  const double rim = hip.acetabulum() ? hip.acetabulum()->rim_radius_mm : hip.head_radius_mm() + 5;
  out.limited_by = p_joint.norm() <= rim + o.intra_articular_margin_mm ? ImpingementSite::intra_articular
                                                                      : ImpingementSite::extra_articular;
  out.limited_by_hidden_vertex = l.hidden;
  // An exact contact is classed by its point (as the exact search classed it), a vertex by the vertex.
  out.contact_class = std::isfinite(l.point.x())
                          ? hip.contact_class_at(p_joint, {R, t}, o.intra_articular_margin_mm)
                          : hip.contact_class(l.ball, static_cast<std::int64_t>(l.vertex), {R, t}, o.intra_articular_margin_mm);
  out.femoral_zone = hip.femoral_zone(R.transpose() * (p_joint - t)), out.pelvic_zone = hip.pelvic_zone(p_joint);
  if (hip.socket_clock()) {
    // On the socket the contact point itself; on the femur the point carried back onto the unposed femur.
    out.socket_clock_h = hip.socket_clock()->hour(p_joint);
    out.femur_clock_h = hip.ball_clock()->hour(R.transpose() * (p_joint - t));
  }
}

// limit_only: only limit_deg, contact_at_start and the counts are wanted (a ROM map's cell), so
// neither end is scanned for the exact least gap and the monotony is not checked.
RomLimit search(const HipJoint& hip, const std::function<Eigen::Matrix3d(double)>& rotation, const RomOptions& o,
                const RomBaseline& base, const RomSearchBounds* bounds, bool limit_only = false) {
  const Joint& joint = hip.joint();
  require(base.skip_ball.size() == static_cast<std::size_t>(joint.ball().relative.rows()) &&
              base.skip_socket.size() == static_cast<std::size_t>(joint.socket().relative.rows()),
          "rom: the baseline belongs to another joint");
  RomLimit out;
  out.excluded_vertices = base.excluded_vertices;
  require(o.vertices != RomVertices::hidden || (joint.ball().layered && joint.socket().layered),
          "rom: counting hidden vertices needs layered maps (JointOptions::layers > 0)");
  const double cut = cut_of(o);
  check_metric(joint, o);
  GapScanner scan(joint, base, bounds, o);
  // The femur's translation by the joint-centre method (a function of the rotation alone).
  auto pose_at = [&](double theta) {
    const Eigen::Matrix3d R = rotation(theta);
    return std::pair{R, hip.joint_translation(R)};
  };
  auto gap_at = [&](double theta, bool exact = false) {
    interruption_point();  // a front end's stop (Ctrl-C in Python), between the search's poses
    ++out.evaluations;
    const auto [R, t] = pose_at(theta);
    return scan(R, t, exact);
  };
  double lo = 0, hi = 0;
  const double start_gap = gap_at(0, !limit_only).gap;
  if (!limit_only) out.min_gap_at_start_mm = std::isinf(start_gap) ? std::numeric_limits<double>::quiet_NaN() : start_gap;
  bool found = start_gap <= cut;
  out.contact_at_start = found;
  out.status = found ? RomLimitStatus::contact_at_start : RomLimitStatus::free;
  for (int k = 1; !found; ++k) {
    const double t = std::min(o.max_deg, k * o.step_deg);
    const double g = gap_at(t).gap;
    if (g <= cut) {
      found = true, hi = t;
    } else {
      lo = t;
      if (t >= o.max_deg) return out;
    }
  }
  while (hi - lo > o.tolerance_deg) {
    const double mid = 0.5 * (lo + hi);
    (gap_at(mid).gap <= cut ? hi : lo) = mid;
  }
  if (!out.contact_at_start) out.status = RomLimitStatus::limited;
  if (limit_only) {
    out.vertices_looked_up = scan.vertices_looked_up();
    out.vertices_skipped = scan.vertices_skipped();
    out.limit_deg = hi;
    out.first_contact_deg = first_contact_of(out, o);
    return out;
  }
  const auto [R, t] = pose_at(hi);
  ++out.evaluations;
  const Least l = scan(R, t, true);  // the least gap and where, not only whether they meet
  // A transient touch: the bones part again one step farther.
  if (hi + o.step_deg <= o.max_deg) out.monotone = gap_at(hi + o.step_deg).gap <= cut;
  out.limit_deg = hi;
  out.first_contact_deg = first_contact_of(out, o);
  out.min_gap_at_limit_mm = l.gap;
  out.joint_translation_mm = hip.femur_translation(t);
  if (std::isfinite(l.point.x()) && !out.contact_at_start) {
    // Exact contacts: at the limit the surfaces cross along a curve; they first touch where they come
    // nearest at the bracket's lower end.
    const auto [R_lo, t_lo] = pose_at(lo);
    ++out.evaluations;
    describe_contact(out, hip, scan(R_lo, t_lo, true), R_lo, t_lo, o);
  } else {
    describe_contact(out, hip, l, R, t, o);
  }
  out.vertices_looked_up = scan.vertices_looked_up();
  out.vertices_skipped = scan.vertices_skipped();
  return out;
}

// The bounds of a search's per-vertex scans (none where it finds contacts exactly).
std::shared_ptr<const RomSearchBounds> search_bounds(const Joint& joint, const RomOptions& o, const RomBaseline& base) {
  return exact_search(o, base) ? nullptr : bounds_for(joint, o, base);
}
RomOptions at_first_touch(RomOptions o) {
  o.contact_depth_mm = 0;
  return o;
}
// The search of one motion with its first touch (RomLimit::first_contact_deg): at a contact depth > 0, a
// search of its own at depth 0 (first_bounds: search_bounds of at_first_touch(o)).
RomLimit with_first_contact(const HipJoint& hip, const std::function<Eigen::Matrix3d(double)>& rotation,
                            const RomOptions& o, const RomBaseline& base, const RomSearchBounds* bounds,
                            const RomSearchBounds* first_bounds) {
  RomLimit l = search(hip, rotation, o, base, bounds);
  if (o.contact_depth_mm > 0)
    l.first_contact_deg = search(hip, rotation, at_first_touch(o), base, first_bounds, true).first_contact_deg;
  return l;
}
}  // namespace

RomLimit find_rom_limit(const HipJoint& hip, const std::function<Eigen::Matrix3d(double)>& rotation,
                        const RomOptions& o, const RomBaseline& base) {
  check(o);
  const std::shared_ptr<const RomSearchBounds> bounds = search_bounds(hip.joint(), o, base);
  const std::shared_ptr<const RomSearchBounds> first =
      o.contact_depth_mm > 0 ? search_bounds(hip.joint(), at_first_touch(o), base) : nullptr;
  return with_first_contact(hip, rotation, o, base, bounds.get(), first.get());
}

RomLimit find_rom_limit(const HipJoint& hip, const std::function<PoseAngles(double)>& motion, const RomOptions& o,
                        const RomBaseline& base) {
  return find_rom_limit(
      hip, std::function<Eigen::Matrix3d(double)>([&](double t) { return hip.femur_rotation(motion(t)); }), o, base);
}

std::vector<RomLimit> find_rom_limits(const HipJoint& hip, const std::vector<StandardMotion>& motions,
                                      const RomOptions& o, const RomBaseline& base) {
  return find_rom_limits(hip, motions, o, base, [&hip](const PoseAngles& a) { return hip.femur_rotation(a); });
}

std::vector<RomLimit> find_rom_limits(const HipJoint& hip, const std::vector<StandardMotion>& motions,
                                      const RomOptions& o, const RomBaseline& base, const PoseRotation& rotation) {
  check(o);
  const std::shared_ptr<const RomSearchBounds> bounds = search_bounds(hip.joint(), o, base);
  const std::shared_ptr<const RomSearchBounds> first =
      o.contact_depth_mm > 0 ? search_bounds(hip.joint(), at_first_touch(o), base) : nullptr;
  std::vector<RomLimit> out(motions.size());
  std::vector<std::string> errors(motions.size());
  const auto n = static_cast<std::int64_t>(motions.size());
#pragma omp parallel for schedule(dynamic, 1)
  for (std::int64_t k = 0; k < n; ++k) {
    try {
      const auto& m = motions[static_cast<std::size_t>(k)];
      RomLimit& limit = out[static_cast<std::size_t>(k)];
      // The way to a start other than neutral: the straight path, parameterised by its largest angle.
      const double way = std::max({std::abs(m.start.flexion_deg), std::abs(m.start.adduction_deg),
                                   std::abs(m.start.internal_rotation_deg)});
      if (way > 0) {
        RomOptions lead = o;
        lead.max_deg = way;
        const PoseAngles s = m.start;
        const RomLimit on_the_way = search(
            hip, std::function<Eigen::Matrix3d(double)>([&](double t) {
              const double f = t / way;
              return rotation({f * s.flexion_deg, f * s.adduction_deg, f * s.internal_rotation_deg});
            }),
            lead, base, bounds.get(), true);
        if (on_the_way.status != RomLimitStatus::free) {
          const double f = on_the_way.limit_deg / way;
          char text[200];
          std::snprintf(text, sizeof text,
                        "the start (flexion %g, adduction %g deg) is not reached: the bones meet at flexion %.1f, "
                        "adduction %.1f deg on the way from neutral",
                        s.flexion_deg, s.adduction_deg, f * s.flexion_deg, f * s.adduction_deg);
          limit = RomLimit{};
          limit.status = RomLimitStatus::not_reachable;
          limit.note = text;
          limit.excluded_vertices = on_the_way.excluded_vertices;
          limit.evaluations = on_the_way.evaluations;
          limit.vertices_looked_up = on_the_way.vertices_looked_up;
          limit.vertices_skipped = on_the_way.vertices_skipped;
          continue;
        }
      }
      limit = with_first_contact(
          hip, std::function<Eigen::Matrix3d(double)>([&](double t) { return rotation(m.angles(t)); }), o, base,
          bounds.get(), first.get());
    } catch (const std::exception& e) {
      errors[static_cast<std::size_t>(k)] = e.what();
    }
  }
  for (const auto& e : errors) require(e.empty(), e);
  return out;
}

std::vector<RomMapCell> rom_map(const HipJoint& hip, const std::vector<double>& flexion,
                                const std::vector<double>& adduction, const RomOptions& o, const RomBaseline& base) {
  check(o);
  const std::shared_ptr<const RomSearchBounds> bounds = search_bounds(hip.joint(), o, base);
  std::vector<RomMapCell> cells;
  for (double f : flexion)
    for (double a : adduction) cells.push_back({f, a, std::numeric_limits<double>::quiet_NaN(), RomMapStatus::free});
  const auto n = static_cast<std::int64_t>(cells.size());
  std::vector<std::string> errors(cells.size());
#pragma omp parallel for schedule(dynamic, 1)
  for (std::int64_t k = 0; k < n; ++k) {
    RomMapCell& c = cells[static_cast<std::size_t>(k)];
    try {
      const RomLimit l = search(hip, std::function<Eigen::Matrix3d(double)>([&](double t) {
                                  return hip.femur_rotation(PoseAngles{c.flexion_deg, c.adduction_deg, t});
                                }),
                                o, base, bounds.get(), true);
      c.vertices_looked_up = l.vertices_looked_up;
      c.vertices_skipped = l.vertices_skipped;
      c.evaluations = l.evaluations;
      c.max_internal_rotation_deg = l.contact_at_start ? std::numeric_limits<double>::quiet_NaN() : l.limit_deg;
      c.status = l.contact_at_start          ? RomMapStatus::contact_at_zero
                 : std::isnan(l.limit_deg) ? RomMapStatus::free
                                           : RomMapStatus::limited;
    } catch (const std::exception& e) {
      errors[static_cast<std::size_t>(k)] = e.what();
    }
  }
  for (const auto& e : errors) require(e.empty(), e);
  return cells;
}

}  // namespace impinge
