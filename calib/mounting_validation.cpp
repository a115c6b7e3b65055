#include "calib/mounting_validation.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <iterator>
#include <limits>
#include <numbers>

#include "core/input_error.hpp"
#include "core/parallel_tasks.hpp"
#include "core/units.hpp"
#include "ims/so3.hpp"

namespace imscal::calib {
namespace {

bool starts_with_any(const std::string& name, std::initializer_list<const char*> prefixes) {
  for (const char* p : prefixes)
    if (name.rfind(p, 0) == 0) return true;
  return false;
}

// Index of the first parameter whose name starts with one of the prefixes, if three such names
// follow each other.
std::optional<std::size_t> block_start(const std::vector<std::string>& names,
                                       std::initializer_list<const char*> prefixes) {
  for (std::size_t i = 0; i + 3 <= names.size(); ++i)
    if (starts_with_any(names[i], prefixes) && starts_with_any(names[i + 1], prefixes) &&
        starts_with_any(names[i + 2], prefixes))
      return i;
  return std::nullopt;
}

const EstimatedVector* find_estimate(const FrameCalibrationResult& r, const std::string& name) {
  for (const auto& e : r.estimates)
    if (e.name.rfind(name, 0) == 0 && e.sigma.size() == 3) return &e;
  return nullptr;
}

// Unit of a reported estimate -> SI factor (only the ones T_S_H is reported in).
double si_factor(const std::string& unit) {
  if (unit == "deg") return kRadPerDeg;
  if (unit == "rad") return 1.0;
  if (unit == "mm") return 1e-3;
  if (unit == "m") return 1.0;
  if (unit == "urad") return 1e-6;
  if (unit == "arcsec") return kRadPerDeg / 3600.0;
  return std::numeric_limits<double>::quiet_NaN();
}

std::string rest_range_text(const std::vector<RestObservation>& rests, std::size_t first,
                            std::size_t last) {
  auto label = [&](std::size_t i) {
    return i < rests.size() && !rests[i].label.empty() ? rests[i].label
                                                       : fmt::format("rest {}", i + 1);
  };
  return fmt::format("{} .. {}", label(first), label(last));
}

std::string difference_text(const MountingDifference& d) {
  return fmt::format("{:.4f} deg and {:.4f} mm ({:.1f} sigma)", d.rotation_rad / kRadPerDeg,
                     d.translation_m * 1e3, d.normalised);
}

std::string max_sigma_text(const MountingEstimate& e) {
  const Eigen::Matrix<double, 6, 1> s = e.covariance.diagonal().cwiseMax(0.0).cwiseSqrt();
  return fmt::format("{:.5f} deg, {:.5f} mm", s.head<3>().maxCoeff() / kRadPerDeg,
                     s.tail<3>().maxCoeff() * 1e3);
}

}  // namespace

const char* to_string(Verdict verdict) {
  switch (verdict) {
    case Verdict::kPass:
      return "pass";
    case Verdict::kWarn:
      return "warn";
    case Verdict::kFail:
      return "fail";
  }
  return "?";
}

MountingEstimate mounting_estimate(const FrameCalibrationResult& result) {
  MountingEstimate e;
  e.T_S_H = result.T_S_H;
  const auto rot = block_start(result.parameter_names, {"R_S_H", "T_S_H.rotation", "T_S_H.rot"});
  const auto pos =
      block_start(result.parameter_names, {"p_S_H", "T_S_H.translation", "T_S_H.position"});
  const auto n = result.covariance.rows();
  if (rot && pos && n == result.covariance.cols() && Eigen::Index(*rot + 3) <= n &&
      Eigen::Index(*pos + 3) <= n && result.covariance.allFinite()) {
    const std::size_t start[2] = {*rot, *pos};
    for (int a = 0; a < 2; ++a)
      for (int b = 0; b < 2; ++b)
        e.covariance.block<3, 3>(3 * a, 3 * b) =
            result.covariance.block<3, 3>(Eigen::Index(start[a]), Eigen::Index(start[b]));
    e.has_covariance = true;
    return e;
  }
  const EstimatedVector* r = find_estimate(result, "T_S_H.rotation");
  const EstimatedVector* t = find_estimate(result, "T_S_H.translation");
  if (r && t) {
    const double fr = si_factor(r->unit), ft = si_factor(t->unit);
    if (std::isfinite(fr) && std::isfinite(ft) && r->sigma.allFinite() && t->sigma.allFinite()) {
      e.covariance.diagonal().head<3>() = (r->sigma * fr).array().square().matrix();
      e.covariance.diagonal().tail<3>() = (t->sigma * ft).array().square().matrix();
      e.has_covariance = true;
    }
  }
  return e;
}

bool MountingDifference::exceeds(double sigma_multiple, const MountingThresholds& t) const {
  return normalised > sigma_multiple && (rotation_rad > t.repeat_rotation_floor_rad ||
                                         translation_m > t.repeat_translation_floor_m);
}

MountingDifference compare_mountings(const MountingEstimate& a, const MountingEstimate& b) {
  MountingDifference d;
  const Eigen::Quaterniond qa(a.T_S_H.rotation()), qb(b.T_S_H.rotation());
  const Eigen::Vector3d rotation = ims::quat_log(Eigen::Quaterniond(qa * qb.conjugate()));
  const Eigen::Vector3d translation = a.T_S_H.translation() - b.T_S_H.translation();
  d.difference << rotation, translation;
  d.rotation_rad = rotation.norm();
  d.translation_m = translation.norm();
  d.combined_sigma = (a.covariance.diagonal() + b.covariance.diagonal()).cwiseMax(0.0).cwiseSqrt();
  d.normalised = 0.0;
  for (int k = 0; k < 6; ++k) {
    const double x = std::abs(d.difference(k));
    if (d.combined_sigma(k) > 0.0)
      d.normalised = std::max(d.normalised, x / d.combined_sigma(k));
    else if (x > 0.0)
      d.normalised = std::numeric_limits<double>::infinity();
  }
  return d;
}

std::vector<std::pair<std::size_t, std::size_t>> rest_segments(std::size_t rest_count,
                                                               std::size_t per_segment,
                                                               std::size_t min_rests) {
  std::vector<std::pair<std::size_t, std::size_t>> out;
  if (per_segment == 0 || rest_count == 0) return out;
  for (std::size_t first = 0; first < rest_count; first += per_segment)
    out.emplace_back(first, std::min(first + per_segment, rest_count) - 1);
  if (out.size() > 1 && out.back().second - out.back().first + 1 < min_rests) {
    out[out.size() - 2].second = out.back().second;
    out.pop_back();
  }
  return out;
}

std::optional<MountingCheck> heading_reference_check(const FrameCalibrationResult& result,
                                                     const MountingThresholds& t) {
  if (!result.heading || !result.heading->reference) return std::nullopt;
  const HeadingEstimate& h = *result.heading;
  const HeadingReference& reference = *h.reference;
  const double difference =
      std::remainder(h.ims_only_yaw_rad - reference.yaw_rad, 2.0 * std::numbers::pi);
  const double combined = std::hypot(h.ims_only_sigma_rad, reference.sigma_rad);
  const double normalised = std::abs(difference) / combined;
  MountingCheck check;
  check.name = "heading_reference";
  check.level = normalised > t.repeat_fail_sigma   ? Verdict::kFail
                : normalised > t.repeat_warn_sigma ? Verdict::kWarn
                                                   : Verdict::kPass;
  check.message = fmt::format(
      "base heading (yaw of T_W_R) {:.4f} +- {:.4f} deg with the reference {:.4f} +- {:.4f} deg "
      "({}); the IMS alone (Earth rate) gives {:.4f} +- {:.4f} deg, {:.4f} deg = {:.1f} combined "
      "sigma from the reference{}",
      h.yaw_rad / kRadPerDeg, h.sigma_rad / kRadPerDeg, reference.yaw_rad / kRadPerDeg,
      reference.sigma_rad / kRadPerDeg, reference.source, h.ims_only_yaw_rad / kRadPerDeg,
      h.ims_only_sigma_rad / kRadPerDeg, difference / kRadPerDeg, normalised,
      check.level == Verdict::kPass
          ? ""
          : ": check the reference (its value, its sign: counterclockwise from East) and that the "
            "base did not turn");
  return check;
}

MountingValidation assess_mounting(const FrameCalibrationResult& combined,
                                   std::vector<SessionPart> halves,
                                   std::vector<SessionPart> segments, const MountingThresholds& t) {
  MountingValidation v;
  v.combined = mounting_estimate(combined);
  v.rest_residuals = combined.rest_residuals;
  v.motion_residuals = combined.motion_residuals;
  v.outliers = combined.outliers;
  v.weak_directions = combined.weak_directions;
  v.halves = std::move(halves);
  v.segments = std::move(segments);
  auto add = [&](std::string name, Verdict level, std::string message) {
    v.checks.push_back({std::move(name), level, std::move(message)});
  };

  // Convergence of the bundle on the whole session.
  if (combined.converged)
    add("convergence", Verdict::kPass,
        fmt::format("the bundle converged in {} iterations", combined.iterations));
  else
    add("convergence", Verdict::kFail,
        fmt::format("the bundle did not converge ({} iterations): the frames are not usable",
                    combined.iterations));

  // Outliers among the rest and motion blocks.
  std::size_t blocks = 0;
  for (const auto* list : {&v.rest_residuals, &v.motion_residuals})
    for (const auto& r : *list) {
      ++blocks;
      v.outlier_count += r.outlier;
    }
  const double fraction = blocks ? double(v.outlier_count) / double(blocks) : 0.0;
  std::string outlier_names;
  for (const auto* list : {&v.rest_residuals, &v.motion_residuals})
    for (const auto& r : *list)
      if (r.outlier)
        outlier_names += fmt::format("{}{} ({:.1f} sigma)", outlier_names.empty() ? "" : ", ",
                                     r.label, r.normalised);
  if (v.outlier_count <= t.max_outliers_pass)
    add("outliers", Verdict::kPass,
        fmt::format("{} of {} rest and motion blocks are outliers", v.outlier_count, blocks));
  else
    add("outliers", fraction > t.max_outlier_fraction_warn ? Verdict::kFail : Verdict::kWarn,
        fmt::format("{} of {} rest and motion blocks are outliers ({:.0f} %): {}; check that the "
                    "robot was still and the sensor firmly mounted there",
                    v.outlier_count, blocks, 100.0 * fraction, outlier_names));

  // Precision of the combined T_S_H.
  if (!v.combined.has_covariance) {
    add("precision", Verdict::kWarn,
        "the bundle reported no covariance of T_S_H: its precision is unknown");
  } else {
    const Eigen::Matrix<double, 6, 1> s =
        v.combined.covariance.diagonal().cwiseMax(0.0).cwiseSqrt();
    const double rot = s.head<3>().maxCoeff(), pos = s.tail<3>().maxCoeff();
    const bool ok = rot <= t.max_rotation_sigma_rad && pos <= t.max_translation_sigma_m &&
                    !combined.covariance_rank_deficient;
    std::string message = fmt::format(
        "1-sigma of T_S_H: {:.5f} deg rotation, {:.5f} mm translation (limits {:.5f} deg, "
        "{:.5f} mm)",
        rot / kRadPerDeg, pos * 1e3, t.max_rotation_sigma_rad / kRadPerDeg,
        t.max_translation_sigma_m * 1e3);
    if (combined.covariance_rank_deficient)
      message += "; the covariance is rank deficient (pose set does not determine every unknown)";
    for (const auto& w : combined.weak_directions)
      if (!ok) message += fmt::format("; weak: {} ({})", w.description, w.suggestion);
    add("precision", ok ? Verdict::kPass : Verdict::kWarn, message);
  }

  // Halves of the session.
  if (v.halves.size() == 2) {
    const auto& h0 = v.halves[0];
    const auto& h1 = v.halves[1];
    if (!h0.calibrated || !h1.calibrated) {
      const auto& bad = h0.calibrated ? h1 : h0;
      add("halves", Verdict::kWarn,
          fmt::format("the {} could not be calibrated alone, so the repeatability between the "
                      "halves is not checked: {}",
                      bad.label, bad.failure));
    } else {
      const MountingDifference d = compare_mountings(h0.estimate, h1.estimate);
      v.halves_difference = d;
      Verdict level = Verdict::kPass;
      if (d.exceeds(t.repeat_fail_sigma, t))
        level = Verdict::kFail;
      else if (d.exceeds(t.repeat_warn_sigma, t))
        level = Verdict::kWarn;
      add("halves", level,
          fmt::format(
              "T_S_H of the {} and the {} differ by {}{}", h0.label, h1.label, difference_text(d),
              level == Verdict::kPass ? "" : ": the mount is not repeatable within the session"));
    }
  }

  // Slipped mount: neighbouring segments.
  if (!v.segments.empty()) {
    std::vector<std::size_t> usable;
    std::string failed;
    for (std::size_t i = 0; i < v.segments.size(); ++i) {
      if (v.segments[i].calibrated)
        usable.push_back(i);
      else
        failed +=
            fmt::format("; {} not calibrated: {}", v.segments[i].label, v.segments[i].failure);
    }
    std::vector<std::string> slips;
    for (std::size_t k = 1; k < usable.size(); ++k) {
      SegmentComparison c;
      c.earlier = usable[k - 1];
      c.later = usable[k];
      c.difference =
          compare_mountings(v.segments[c.earlier].estimate, v.segments[c.later].estimate);
      c.slipped = c.difference.exceeds(t.slip_sigma, t);
      if (c.slipped) {
        const auto& a = v.segments[c.earlier];
        const auto& b = v.segments[c.later];
        slips.push_back(fmt::format(
            "mount slipped between rest {} and rest {}: T_S_H of {} and of {} differ by {}",
            a.last_rest + 1, b.first_rest + 1, a.label, b.label, difference_text(c.difference)));
      }
      v.segment_comparisons.push_back(c);
    }
    if (!slips.empty()) {
      for (auto& s : slips) add("slip", Verdict::kFail, s);
    } else if (usable.size() < 2) {
      add("slip", Verdict::kWarn,
          fmt::format("fewer than 2 segments could be calibrated: a slipped mount cannot be "
                      "detected{}",
                      failed));
    } else {
      double worst = 0.0;
      for (const auto& c : v.segment_comparisons) worst = std::max(worst, c.difference.normalised);
      add("slip", failed.empty() ? Verdict::kPass : Verdict::kWarn,
          fmt::format("{} segments agree (largest difference {:.1f} sigma){}", usable.size(), worst,
                      failed));
    }
  }

  if (auto heading = heading_reference_check(combined, t)) v.checks.push_back(*heading);

  for (const auto& c : v.checks) {
    v.verdict = std::max(v.verdict, c.level);
    if (c.level != Verdict::kPass) v.reasons.push_back(c.message);
  }
  if (v.reasons.empty())
    v.reasons.push_back(
        fmt::format("all checks passed; T_S_H 1-sigma {}",
                    v.combined.has_covariance ? max_sigma_text(v.combined) : "unknown"));
  return v;
}

namespace {

// The rests [first, last] of `input` without the robot joint series: a part is judged on its
// T_S_H alone, and the clock offset's rate windows (the only residuals the joint series feeds)
// share no unknown with the frames (calib/frame_bundle.hpp), so the part's T_S_H and its
// covariance are those of the bundle with them. Without them a part costs what its own rests
// cost, instead of the whole record's rate windows and flange-rate grid again.
FrameCalibrationInput part_input(const FrameCalibrationInput& input, std::size_t first_rest,
                                 std::size_t last_rest) {
  FrameCalibrationInput sub;
  sub.imu = input.imu;
  sub.site = input.site;
  sub.kinematics = input.kinematics;
  sub.rests.assign(input.rests.begin() + std::ptrdiff_t(first_rest),
                   input.rests.begin() + std::ptrdiff_t(last_rest) + 1);
  sub.noise = input.noise;
  sub.time_offset_initial_s = input.time_offset_initial_s;
  sub.source = input.source;
  sub.first_rest_position_W_m = input.first_rest_position_W_m;
  sub.known_frames = input.known_frames;
  sub.heading_reference = input.heading_reference;
  return sub;
}

}  // namespace

SessionPart calibrate_part(const FrameCalibrationInput& input,
                           const FrameCalibrationOptions& options, std::size_t first_rest,
                           std::size_t last_rest, std::string label) {
  SessionPart part;
  part.label = std::move(label);
  part.first_rest = first_rest;
  part.last_rest = last_rest;
  if (last_rest >= input.rests.size() || first_rest > last_rest) {
    part.failure = "rest range outside the session";
    return part;
  }
  FrameCalibrationInput sub = part_input(input, first_rest, last_rest);
  try {
    const FrameCalibrationResult r = calibrate_frames(sub, options);
    part.calibrated = true;
    part.converged = r.converged;
    part.estimate = mounting_estimate(r);
    if (!r.converged) {
      part.calibrated = false;
      part.failure = "the bundle did not converge on these rests";
    }
  } catch (const InputError& e) {
    part.failure = e.problem();
  }
  return part;
}

MountingValidation validate_mounting(const FrameCalibrationInput& input,
                                     const FrameCalibrationOptions& options,
                                     const FrameCalibrationResult& combined,
                                     const MountingValidationOptions& vo,
                                     const ValidationProgress& progress) {
  const std::size_t n = input.rests.size();
  std::vector<std::pair<std::size_t, std::size_t>> half_ranges, segment_ranges;
  if (vo.check_halves && n >= 2) half_ranges = {{0, n / 2 - 1}, {n / 2, n - 1}};
  if (vo.check_segments) segment_ranges = rest_segments(n, vo.segment_rests);
  if (segment_ranges.size() < 2) segment_ranges.clear();  // one segment: nothing to compare
  const double total = double(half_ranges.size() + segment_ranges.size());
  double done = 0.0;
  auto report = [&](const char* stage) {
    if (progress) progress(stage, total > 0 ? done / total : 1.0);
  };
  FrameCalibrationOptions part_options = options;
  part_options.report_progress = false;

  // The halves and segments are independent bundles: on the cores (core/parallel_tasks.hpp), each
  // into its own slot.
  std::vector<std::pair<std::size_t, std::size_t>> ranges = half_ranges;
  ranges.insert(ranges.end(), segment_ranges.begin(), segment_ranges.end());
  std::vector<SessionPart> parts(ranges.size());
  report(half_ranges.empty() ? "segments" : "halves");
  run_parallel_tasks(ranges.size(), [&](std::size_t i) {
    const auto [first, last] = ranges[i];
    const std::string where = rest_range_text(input.rests, first, last);
    const std::string label =
        i < half_ranges.size() ? fmt::format("{} half ({})", i == 0 ? "first" : "second", where)
                               : fmt::format("segment {} ({})", i - half_ranges.size() + 1, where);
    parts[i] = calibrate_part(input, part_options, first, last, label);
  });
  done = total;
  std::vector<SessionPart> halves(
      std::make_move_iterator(parts.begin()),
      std::make_move_iterator(parts.begin() + std::ptrdiff_t(half_ranges.size())));
  std::vector<SessionPart> segments(
      std::make_move_iterator(parts.begin() + std::ptrdiff_t(half_ranges.size())),
      std::make_move_iterator(parts.end()));
  report("segments");
  return assess_mounting(combined, std::move(halves), std::move(segments), vo.thresholds);
}

MountingCheck compare_sessions(const FrameCalibrationResult& first,
                               const FrameCalibrationResult& second, const MountingThresholds& t) {
  const MountingDifference d =
      compare_mountings(mounting_estimate(first), mounting_estimate(second));
  MountingCheck c;
  c.name = "sessions";
  if (d.exceeds(t.repeat_fail_sigma, t))
    c.level = Verdict::kFail;
  else if (d.exceeds(t.repeat_warn_sigma, t))
    c.level = Verdict::kWarn;
  c.message =
      fmt::format("T_S_H of the two sessions differ by {}{}", difference_text(d),
                  c.level == Verdict::kPass ? "" : ": the mount was not re-seated repeatably");
  return c;
}

}  // namespace imscal::calib
