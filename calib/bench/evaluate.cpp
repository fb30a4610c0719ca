#include "rigcal/bench/evaluate.h"

#include <fmt/format.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <cmath>

#include "rigcal/core/error.h"
#include "rigcal/core/memory.h"

namespace rigcal::bench {
namespace {

constexpr double kDeg = 180.0 / M_PI;

Association default_association(Convention c, const Trajectory& gt, const Trajectory& est) {
  if (!gt.has_stamps || !est.has_stamps) return Association::index;
  switch (c) {
    case Convention::rigcal:
      return Association::interpolate;
    case Convention::kitti:
      return Association::one_to_one;
    case Convention::evo:
    case Convention::vbr:
      return Association::nearest;
  }
  return Association::nearest;
}

Alignment default_alignment(Convention c) {
  return c == Convention::rigcal || c == Convention::vbr ? Alignment::se3 : Alignment::none;
}

// The KITTI devkit's segment errors, in double: general 4x4 inverses (the devkit inverts
// matrices, it does not transpose them) and the rotation angle as acos((trace - 1) / 2).
std::vector<Segment> kitti_devkit_segments(const std::vector<SE3>& gt,
                                           const std::vector<SE3>& est) {
  std::vector<Segment> out;
  const std::vector<double> dist = cumulative_distances(gt);
  for (size_t first = 0; first < gt.size(); first += 10) {
    for (double len : kKittiLengths) {
      const auto it = std::upper_bound(dist.begin() + first, dist.end(), dist[first] + len);
      if (it == dist.end()) continue;
      const size_t last = it - dist.begin();
      const Eigen::Matrix4d d_gt = gt[first].matrix().inverse() * gt[last].matrix();
      const Eigen::Matrix4d d_est = est[first].matrix().inverse() * est[last].matrix();
      const Eigen::Matrix4d E = d_est.inverse() * d_gt;
      const double d = 0.5 * (E(0, 0) + E(1, 1) + E(2, 2) - 1.0);
      const double r = std::acos(std::max(std::min(d, 1.0), -1.0));
      out.push_back({first, last, len, E.topRightCorner<3, 1>().norm(), r * kDeg});
    }
  }
  return out;
}

RpeResult make_rpe(std::string kind, std::string definition, std::vector<Segment> segments,
                   bool keep) {
  RpeResult r;
  r.kind = std::move(kind);
  r.definition = std::move(definition);
  r.drift = pooled_drift(segments);
  std::vector<double> t, a;
  reserve_huge(t, segments.size());
  reserve_huge(a, segments.size());
  for (const Segment& s : segments) {
    t.push_back(s.trans);
    a.push_back(s.rot_deg);
  }
  r.trans = statistics(std::move(t));
  r.rot_deg = statistics(std::move(a));
  if (keep) r.segments = std::move(segments);
  return r;
}

std::string delta_definition(const EvalOptions& o) {
  const bool path = o.delta_unit == DeltaUnit::meters;
  const bool frames = o.delta_unit == DeltaUnit::frames;
  return fmt::format(
      "{} pairs {:g} {}{} apart{}", o.all_pairs ? "all" : "consecutive", o.delta,
      frames ? "frame(s)" : to_string(o.delta_unit),
      frames ? ""
             : fmt::format(" of the {}'s {}", o.pairs_from_reference ? "ground truth" : "estimate",
                           path ? "path" : "rotation"),
      !frames && o.all_pairs ? fmt::format(" (+-{:g} %)", 100.0 * o.delta_tol) : "");
}

std::vector<std::pair<size_t, size_t>> delta_pairs(const std::vector<SE3>& gt,
                                                   const std::vector<SE3>& est,
                                                   const EvalOptions& o) {
  std::vector<std::pair<size_t, size_t>> pairs = evo_delta_pairs(
      o.pairs_from_reference ? gt : est, o.delta, o.delta_unit, o.all_pairs, o.delta_tol);
  if (pairs.empty()) {
    throw Error(fmt::format(
        "RPE delta {:g} {} gives no pose pair on this trajectory; use a smaller --delta{}", o.delta,
        to_string(o.delta_unit), o.all_pairs ? " or a larger --delta-tol" : ""));
  }
  return pairs;
}

// Like make_rpe for fixed-length segments, from their errors only (16 bytes a segment, not the
// whole segment, for the medians).
RpeResult length_rpe(std::string kind, std::string definition, const std::vector<SE3>& gt,
                     const std::vector<SE3>& est, const std::vector<double>& lengths, size_t step,
                     bool keep) {
  RpeResult r;
  r.kind = std::move(kind);
  r.definition = std::move(definition);
  SegmentErrors e = length_segment_errors(gt, est, lengths, step, keep ? &r.segments : nullptr);
  r.drift.n_segments = e.trans.size();
  if (!e.trans.empty()) {
    r.drift.trans_pct = 100.0 * e.trans_per_length / static_cast<double>(e.trans.size());
    r.drift.rot_deg_per_m = e.rot_deg_per_length / static_cast<double>(e.trans.size());
  }
  tbb::parallel_invoke([&] { r.trans = statistics_in_place(e.trans); },
                       [&] { r.rot_deg = statistics_in_place(e.rot_deg); });
  return r;
}

// ---- The VBR evaluator, reproduced in float (vbr_benchmark.cpp)
// ----------------------------------
struct VbrFigures {
  double rpe_trans_pct = 0, rpe_rot_deg_per_m = 0, ate_trans = 0, ate_rot = 0;
  size_t n_segments = 0;
  std::vector<size_t> matched;  // estimate index per GT pose
  // The float matching against the same walk on the exact stamps: GT poses paired otherwise, and
  // the largest stamp difference of a float pair (s).
  size_t n_rematched = 0;
  double worst_pair_dt_s = 0;
};

// The evaluator's walk: for each GT stamp, forward to the nearest estimate stamp (ties: later).
template <class Stamp, class Diff>
std::vector<size_t> vbr_walk(const std::vector<Stamp>& t_gt, const std::vector<Stamp>& t_est,
                             Diff diff) {
  std::vector<size_t> matched;
  matched.reserve(t_gt.size());
  size_t k = 0;
  for (size_t i = 0; i < t_gt.size(); ++i) {
    auto min_delta = diff(t_est[k], t_gt[i]);
    while (k + 1 < t_est.size() && diff(t_est[k + 1], t_gt[i]) <= min_delta) {
      min_delta = diff(t_est[k + 1], t_gt[i]);
      ++k;
    }
    matched.push_back(k);
  }
  return matched;
}

// The evaluator reads each pose as float and builds its rotation from the float quaternion.
Eigen::Isometry3f to_float(const SE3& T) {
  Eigen::Isometry3f out = Eigen::Isometry3f::Identity();
  out.linear() = Eigen::Quaternionf(Eigen::Quaterniond(T.R).cast<float>()).toRotationMatrix();
  out.translation() = T.t.cast<float>();
  return out;
}

// The angle in float, returned (and summed) in double, as the evaluator does.
double vbr_rotation_error_deg(const Eigen::Isometry3f& E) {
  Eigen::Quaternionf q(E.linear());
  q.normalize();
  const double rad = Eigen::Quaternionf(1.0f, 0.0f, 0.0f, 0.0f).angularDistance(q);
  return rad * (180.0f / M_PI);
}

VbrFigures vbr_evaluator(const Trajectory& gt, const Trajectory& est) {
  VbrFigures f;
  std::vector<float> t_gt(gt.size()), t_est(est.size());
  for (size_t i = 0; i < gt.size(); ++i) t_gt[i] = static_cast<float>(gt.stamps[i].seconds());
  for (size_t i = 0; i < est.size(); ++i) t_est[i] = static_cast<float>(est.stamps[i].seconds());
  // Nearest estimate stamp per GT pose, walking forward, no threshold; in float as the evaluator
  // reads its stamps, and again on the exact stamps to tell what float costs.
  f.matched = vbr_walk(t_gt, t_est, [](float a, float b) { return std::abs(a - b); });
  const std::vector<size_t> exact = vbr_walk(
      gt.stamps, est.stamps, [](Time a, Time b) { return a < b ? (b - a).ns : (a - b).ns; });
  for (size_t i = 0; i < gt.size(); ++i) {
    const double dt = std::abs((est.stamps[f.matched[i]] - gt.stamps[i]).seconds());
    f.worst_pair_dt_s = std::max(f.worst_pair_dt_s, dt);
    if (f.matched[i] != exact[i]) ++f.n_rematched;
  }
  std::vector<Eigen::Isometry3f> P_gt(gt.size()), P_es(gt.size());
  for (size_t i = 0; i < gt.size(); ++i) {
    P_gt[i] = to_float(gt.T_world_body[i]);
    P_es[i] = to_float(est.T_world_body[f.matched[i]]);
  }
  // RPE over fractions of the GT length, every frame a start: poses and segments in float, the
  // sums in double (a float sum of millions of segments drifts: 1.7 % at 1M poses).
  std::vector<float> dist(gt.size(), 0.0f);
  for (size_t i = 1; i < gt.size(); ++i) {
    dist[i] = dist[i - 1] + (P_gt[i - 1].translation() - P_gt[i].translation()).norm();
  }
  std::vector<float> lengths;
  for (double p : kVbrFractions) lengths.push_back(dist.back() * static_cast<float>(p));
  double t_sum = 0.0, r_sum = 0.0;
  size_t n = 0;
  for (size_t first = 0; first < gt.size(); ++first) {
    for (float len : lengths) {
      const auto it = std::upper_bound(dist.begin() + first, dist.end(), dist[first] + len);
      if (it == dist.end()) continue;
      const size_t last = it - dist.begin();
      const Eigen::Isometry3f d_gt = P_gt[first].inverse() * P_gt[last];
      const Eigen::Isometry3f d_es = P_es[first].inverse() * P_es[last];
      const Eigen::Isometry3f E = d_es.inverse() * d_gt;
      r_sum += vbr_rotation_error_deg(E) / len;
      t_sum += static_cast<double>(E.translation().norm()) / len;
      ++n;
    }
  }
  f.n_segments = n;
  f.rpe_rot_deg_per_m = r_sum / static_cast<double>(n);
  f.rpe_trans_pct = 100 * t_sum / static_cast<double>(n);
  // ATE: float Umeyama SE(3) of the matched estimate onto the GT, then sqrt(mean |e|).
  Eigen::Matrix<float, 3, Eigen::Dynamic> X(3, gt.size()), Y(3, gt.size());
  for (size_t i = 0; i < gt.size(); ++i) {
    X.col(i) = P_es[i].translation();
    Y.col(i) = P_gt[i].translation();
  }
  const Eigen::Matrix4f A = Eigen::umeyama(X, Y, false);
  Eigen::Isometry3f T_align(A.block<3, 3>(0, 0));
  T_align.translation() = A.block<3, 1>(0, 3);
  double at = 0.0, ar = 0.0;
  for (size_t i = 0; i < gt.size(); ++i) {
    const Eigen::Isometry3f E = P_gt[i].inverse() * (T_align * P_es[i]);
    ar += vbr_rotation_error_deg(E);
    at += E.translation().norm();
  }
  f.ate_trans = std::sqrt(at / static_cast<double>(gt.size()));
  f.ate_rot = std::sqrt(ar / static_cast<double>(gt.size()));
  return f;
}

}  // namespace

Convention convention_from_string(std::string_view name) {
  for (Convention c : {Convention::rigcal, Convention::evo, Convention::kitti, Convention::vbr}) {
    if (name == to_string(c)) return c;
  }
  throw Error(fmt::format("unknown convention '{}'; expected rigcal, evo, kitti or vbr", name));
}

std::string_view to_string(Convention convention) {
  switch (convention) {
    case Convention::rigcal:
      return "rigcal";
    case Convention::evo:
      return "evo";
    case Convention::kitti:
      return "kitti";
    case Convention::vbr:
      return "vbr";
  }
  return "?";
}

Association association_from_string(std::string_view name) {
  for (Association a : {Association::interpolate, Association::nearest, Association::one_to_one,
                        Association::index}) {
    if (name == to_string(a)) return a;
  }
  throw Error(fmt::format(
      "unknown association '{}'; expected interpolate, nearest, one_to_one or index", name));
}

std::string_view to_string(Association association) {
  switch (association) {
    case Association::interpolate:
      return "interpolate";
    case Association::nearest:
      return "nearest";
    case Association::one_to_one:
      return "one_to_one";
    case Association::index:
      return "index";
  }
  return "?";
}

namespace {

// evo's reduce_to_time_range on the ground truth: the poses whose float64 seconds are within
// [t_start, t_end] (each bound defaulting to the first or last stamp). Returns the note.
std::string crop_to_time_range(Trajectory& gt, const EvalOptions& o) {
  const std::vector<double> s = evo_seconds(gt.stamps, o.gt_stamps_ns);
  const double lo = o.t_start.value_or(s.front()), hi = o.t_end.value_or(s.back());
  if (o.t_start && o.t_end && lo > hi) {
    throw Error(fmt::format("--t-start {} s is after --t-end {} s", lo, hi));
  }
  Trajectory kept;
  for (size_t i = 0; i < s.size(); ++i) {
    if (lo <= s[i] && s[i] <= hi) {
      kept.stamps.push_back(gt.stamps[i]);
      kept.T_world_body.push_back(gt.T_world_body[i]);
    }
  }
  if (kept.empty()) {
    throw Error(
        fmt::format("no ground-truth pose between --t-start and --t-end ({}..{} s); its stamps "
                    "run {}..{} s",
                    lo, hi, to_seconds_text(gt.stamps.front()), to_seconds_text(gt.stamps.back())));
  }
  const std::string note =
      fmt::format("ground truth cropped to {}..{} s (evo's --t_start/--t_end): {} of {} poses", lo,
                  hi, kept.size(), gt.size());
  gt = std::move(kept);
  return note;
}

}  // namespace

const RpeResult* find_rpe(const EvalResult& result, std::string_view kind) {
  for (const RpeResult& r : result.rpe) {
    if (r.kind == kind) return &r;
  }
  return nullptr;
}

EvalResult evaluate(Trajectory gt, Trajectory est, const EvalOptions& opt) {
  if (gt.empty()) throw Error("the ground truth has no poses");
  if (est.empty()) throw Error("the estimate has no poses");
  EvalResult res;
  res.convention = opt.convention;
  res.n_gt = gt.size();
  res.n_est = est.size();
  res.association = opt.association.value_or(default_association(opt.convention, gt, est));
  res.has_stamps = gt.has_stamps && est.has_stamps;
  const Alignment alignment = opt.alignment.value_or(default_alignment(opt.convention));
  if (res.association != Association::index && (!gt.has_stamps || !est.has_stamps)) {
    throw Error(
        fmt::format("association '{}' needs stamps on both trajectories; KITTI files "
                    "without a times file pair by index",
                    to_string(res.association)));
  }
  if ((opt.t_start || opt.t_end || opt.t_offset != 0.0) && !res.has_stamps) {
    throw Error("--t-start, --t-end and --t-offset need stamps on both trajectories");
  }
  if (opt.t_start || opt.t_end) res.notes.push_back(crop_to_time_range(gt, opt));
  if (opt.t_offset != 0.0) {
    res.notes.push_back(fmt::format("{:g} s added to the estimate's stamps", opt.t_offset));
    // Under evo's pairing the offset is applied in evo's float64 seconds (below).
    if (!(opt.convention == Convention::evo && res.association == Association::nearest)) {
      const Time offset = Time::from_seconds(opt.t_offset);
      for (Time& t : est.stamps) t = t + offset;
    }
  }
  const std::string overlap =
      gt.has_stamps && est.has_stamps
          ? fmt::format("GT {}..{} s, estimate {}..{} s", to_seconds_text(gt.stamps.front()),
                        to_seconds_text(gt.stamps.back()), to_seconds_text(est.stamps.front()),
                        to_seconds_text(est.stamps.back()))
          : std::string("no stamps");

  std::optional<VbrFigures> vbr;
  if (opt.convention == Convention::vbr) {
    if (!gt.has_stamps || !est.has_stamps)
      throw Error("the vbr convention needs stamped trajectories");
    vbr = vbr_evaluator(gt, est);
    // Stamps since the UNIX epoch (1.7e9 s) are 128 s apart in float: the evaluator pairs nearly
    // every pose with the wrong one and its figures mean nothing.
    const double t_max =
        std::max(std::abs(gt.stamps.back().seconds()), std::abs(gt.stamps.front().seconds()));
    const float f_max = static_cast<float>(t_max);
    const double spacing = std::nextafter(f_max, INFINITY) - f_max;
    const double interval =
        gt.size() > 1 ? (gt.stamps.back() - gt.stamps.front()).seconds() / double(gt.size() - 1)
                      : 0.0;
    if (vbr->n_rematched > 0 && spacing >= 0.5 * interval) {
      throw Error(fmt::format(
          "the VBR evaluator reads stamps as float: near {:.0f} s floats are {:g} s apart, over "
          "half the ground truth's {:.3g} s between poses, and it pairs {} of {} ground-truth "
          "poses with another estimate pose than the nearest (up to {:.3g} s away). Its figures "
          "on these stamps mean nothing: subtract the first stamp from both files, or use "
          "--convention rigcal",
          t_max, spacing, interval, vbr->n_rematched, gt.size(), vbr->worst_pair_dt_s));
    }
    if (vbr->n_rematched > 0) {
      res.notes.push_back(fmt::format(
          "warning: the evaluator's float stamps pair {} of {} ground-truth poses with another "
          "estimate pose than the nearest (up to {:.3g} s away); its figures carry that",
          vbr->n_rematched, gt.size(), vbr->worst_pair_dt_s));
    }
  }

  // Matched poses. The inputs are released once matched: 1e6 poses are ~100 MB a copy.
  std::vector<SE3> m_gt, m_est;
  std::vector<Time> m_stamps;
  if (res.association == Association::interpolate) {
    Interpolated in = interpolate_gt(gt, est, opt.max_gap);
    m_gt = std::move(in.T_world_gt);
    gt = Trajectory{};
    if (!in.est.empty() && in.est.back() - in.est.front() + 1 == in.est.size()) {
      // A run of consecutive estimate poses (the usual case): moved, not copied.
      const auto first = static_cast<std::ptrdiff_t>(in.est.front());
      const auto end = static_cast<std::ptrdiff_t>(in.est.back() + 1);
      m_est = std::move(est.T_world_body);
      m_stamps = std::move(est.stamps);
      m_est.erase(m_est.begin() + end, m_est.end());
      m_est.erase(m_est.begin(), m_est.begin() + first);
      m_stamps.erase(m_stamps.begin() + end, m_stamps.end());
      m_stamps.erase(m_stamps.begin(), m_stamps.begin() + first);
    } else {
      reserve_huge(m_est, in.est.size());
      reserve_huge(m_stamps, in.est.size());
      for (size_t i : in.est) {
        m_est.push_back(est.T_world_body[i]);
        m_stamps.push_back(est.stamps[i]);
      }
    }
    res.notes.push_back(fmt::format(
        "ground truth interpolated (slerp + linear) at the estimate's stamps inside GT intervals "
        "up to {} s",
        opt.max_gap.seconds()));
  } else if (vbr && res.association == Association::nearest) {
    m_est.reserve(gt.size());
    for (size_t i = 0; i < gt.size(); ++i) m_est.push_back(est.T_world_body[vbr->matched[i]]);
    m_gt = std::move(gt.T_world_body);
    m_stamps = std::move(gt.stamps);
    res.notes.push_back(
        "VBR evaluator: every GT pose takes the nearest estimate stamp, with no threshold; "
        "stamps compared in float");
  } else if (res.association == Association::index) {
    if (gt.size() != est.size()) {
      throw Error(
          fmt::format("pairing by index needs as many poses in both: {} in the ground "
                      "truth, {} in the estimate (give stamps, or a KITTI times file)",
                      gt.size(), est.size()));
    }
    m_gt = std::move(gt.T_world_body);
    m_est = std::move(est.T_world_body);
    m_stamps = std::move(gt.stamps);
  } else {
    Matches m;
    if (res.association == Association::nearest && opt.convention == Convention::evo) {
      m = associate_evo_seconds(evo_seconds(gt.stamps, opt.gt_stamps_ns),
                                evo_seconds(est.stamps, opt.est_stamps_ns), opt.max_diff.seconds(),
                                opt.t_offset);
      res.notes.push_back(fmt::format(
          "each stamp of the shorter trajectory takes the nearest of the longer within {} s, in "
          "float64 seconds as evo reads them, the first of equal stamps (evo's rule, not "
          "one-to-one)",
          opt.max_diff.seconds()));
    } else if (res.association == Association::nearest) {
      m = associate_evo(gt, est, opt.max_diff);
      res.notes.push_back(fmt::format(
          "each stamp of the shorter trajectory takes the nearest of the longer within {} s "
          "(evo's rule, not one-to-one)",
          opt.max_diff.seconds()));
    } else {
      m = associate_one_to_one(gt, est, opt.max_diff);
      res.notes.push_back(
          fmt::format("one-to-one pairs within {} s, closest first", opt.max_diff.seconds()));
    }
    // One side at a time, releasing each input once copied: the peak holds one copy less.
    reserve_huge(m_gt, m.gt.size()), reserve_huge(m_stamps, m.gt.size());
    for (size_t k : m.gt) m_gt.push_back(gt.T_world_body[k]), m_stamps.push_back(gt.stamps[k]);
    gt = Trajectory{};
    reserve_huge(m_est, m.est.size());
    for (size_t k : m.est) m_est.push_back(est.T_world_body[k]);
  }
  gt = Trajectory{};
  est = Trajectory{};

  res.n_pairs = m_gt.size();
  if (res.n_pairs == 0) {
    throw Error(
        fmt::format("no pose pairs: the trajectories do not overlap in time ({}, association {})",
                    overlap, to_string(res.association)));
  }
  // rigcal re-orthonormalises rotations read with few digits; the peers use them as read.
  // (A quaternion's matrix is orthonormal to rounding already: only the others take the SVD.)
  if (opt.convention == Convention::rigcal) {
    for (std::vector<SE3>* poses : {&m_gt, &m_est}) {
      tbb::parallel_for(tbb::blocked_range<size_t>(0, poses->size(), 4096), [&](const auto& r) {
        for (size_t i = r.begin(); i < r.end(); ++i) {
          Eigen::Matrix3d& R = (*poses)[i].R;
          if (orthonormality_error(R) > 1e-13) R = nearest_rotation_near(R);
        }
      });
    }
  }

  res.alignment = align(m_gt, m_est, alignment, opt.align_first_n);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, m_est.size(), 4096), [&](const auto& r) {
    for (size_t i = r.begin(); i < r.end(); ++i) m_est[i] = apply(res.alignment, m_est[i]);
  });  // aligned in place from here on

  PoseErrors ate = absolute_errors(m_gt, m_est);
  res.ate_trans = statistics(ate.trans);
  res.ate_rot_deg = statistics(opt.keep_per_pose ? ate.rot_deg : std::move(ate.rot_deg));
  res.gt_length = cumulative_distances(m_gt).back();
  if (opt.keep_per_pose) {
    res.stamps = std::move(m_stamps);
    res.ate_trans_errors = std::move(ate.trans);
    res.ate_rot_errors_deg = std::move(ate.rot_deg);
    reserve_huge(res.p_gt, m_gt.size()), reserve_huge(res.p_est_aligned, m_gt.size());
    for (size_t i = 0; i < m_gt.size(); ++i) {
      res.p_gt.push_back(m_gt[i].t);
      res.p_est_aligned.push_back(m_est[i].t);
    }
  }
  ate = PoseErrors{};

  const bool keep = opt.keep_segments;
  const std::vector<double> kitti_lengths(std::begin(kKittiLengths), std::end(kKittiLengths));
  switch (opt.convention) {
    case Convention::rigcal: {
      std::vector<double> lengths;
      for (double f : kVbrFractions) lengths.push_back(f * res.gt_length);
      res.rpe.push_back(
          length_rpe("kitti", "KITTI: segments of 100..800 m of GT path, a start every 10 frames",
                     m_gt, m_est, kitti_lengths, 10, keep));
      res.rpe.push_back(length_rpe(
          "vbr",
          "VBR: segments of 1, 2, 3, 5, 8, 13, 21, 34, 55 % of the GT length, every frame a start",
          m_gt, m_est, lengths, 1, keep));
      res.rpe.push_back(make_rpe("delta", delta_definition(opt),
                                 delta_errors(m_gt, m_est, delta_pairs(m_gt, m_est, opt)),
                                 keep || opt.keep_per_pose));
      res.notes.push_back(
          "rigcal: rotations re-orthonormalised; ATE is the true RMSE; RPE pooled over segments");
      break;
    }
    case Convention::evo:
      res.rpe.push_back(make_rpe("delta", "evo_rpe: " + delta_definition(opt) + ", E = inv(dQ) dP",
                                 delta_errors(m_gt, m_est, delta_pairs(m_gt, m_est, opt)),
                                 keep || opt.keep_per_pose));
      res.notes.push_back(
          "evo: APE and RPE as evo_ape / evo_rpe compute them; rotation angles from the log map");
      break;
    case Convention::kitti:
      res.rpe.push_back(make_rpe(
          "kitti",
          "KITTI devkit: 100..800 m every 10 frames, general inverses, acos angles, in double",
          kitti_devkit_segments(m_gt, m_est), keep));
      res.notes.push_back("kitti: the devkit's metric in double (the devkit itself sums in float)");
      break;
    case Convention::vbr: {
      RpeResult r;
      r.kind = "vbr";
      r.definition = "VBR evaluator: 1..55 % of the GT length, every frame a start, in float";
      r.drift.n_segments = vbr->n_segments;
      r.drift.trans_pct = vbr->rpe_trans_pct;
      r.drift.rot_deg_per_m = vbr->rpe_rot_deg_per_m;
      res.rpe.push_back(r);
      res.vbr_ate_trans = vbr->ate_trans;
      res.vbr_ate_rot = vbr->ate_rot;
      res.notes.push_back(fmt::format(
          "vbr: the evaluator's \"ATE RMSE\" is sqrt(mean |e|) = {:.6g} m, not an RMSE; the true "
          "RMSE after the same alignment is {:.6g} m",
          vbr->ate_trans, res.ate_trans.rmse));
      break;
    }
  }
  return res;
}

}  // namespace rigcal::bench
