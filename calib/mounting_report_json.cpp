#include "calib/mounting_report_json.hpp"

#include <fmt/format.h>

#include <cmath>
#include <limits>
#include <numbers>

#include "calib/calibration_json.hpp"
#include "core/json_fields.hpp"
#include "core/units.hpp"

namespace imscal::calib {
namespace {

using nlohmann::json;

constexpr const char* kVersionKey = "imscal-mounting-report";

json residual_json(const PoseResidual& r) {
  return {{"label", r.label},
          {"normalised", r.normalised},
          {"rotation_deg", r.rotation_rad / kRadPerDeg},
          {"position_mm", r.position_m * 1e3},
          {"outlier", r.outlier}};
}

json mounting_json(const MountingEstimate& e) {
  const Eigen::Matrix<double, 6, 1> s = e.covariance.diagonal().cwiseMax(0.0).cwiseSqrt();
  json j = {{"T_S_H", pose_json(e.T_S_H)}};
  if (e.has_covariance) {
    j["sigma_rotation_deg"] = vector_json(s.head<3>(), 1.0 / kRadPerDeg);
    j["sigma_translation_mm"] = vector_json(s.tail<3>(), 1e3);
  }
  return j;
}

json difference_json(const MountingDifference& d) {
  return {
      {"rotation_deg", d.rotation_rad / kRadPerDeg},
      {"translation_mm", d.translation_m * 1e3},
      {"difference_rotation_deg", vector_json(d.difference.head<3>(), 1.0 / kRadPerDeg)},
      {"difference_translation_mm", vector_json(d.difference.tail<3>(), 1e3)},
      {"combined_sigma_rotation_deg", vector_json(d.combined_sigma.head<3>(), 1.0 / kRadPerDeg)},
      {"combined_sigma_translation_mm", vector_json(d.combined_sigma.tail<3>(), 1e3)},
      {"normalised_sigma", std::isfinite(d.normalised) ? json(d.normalised) : json(nullptr)}};
}

json part_json(const SessionPart& p) {
  json j = {{"label", p.label},
            {"first_rest", p.first_rest + 1},
            {"last_rest", p.last_rest + 1},
            {"calibrated", p.calibrated}};
  if (p.calibrated)
    j["estimate"] = mounting_json(p.estimate);
  else
    j["failure"] = p.failure;
  return j;
}

json thresholds_json(const MountingThresholds& t, std::size_t segment_rests) {
  return {{"max_outliers_pass", t.max_outliers_pass},
          {"max_outlier_fraction_warn", t.max_outlier_fraction_warn},
          {"repeat_warn_sigma", t.repeat_warn_sigma},
          {"repeat_fail_sigma", t.repeat_fail_sigma},
          {"repeat_rotation_floor_deg", t.repeat_rotation_floor_rad / kRadPerDeg},
          {"repeat_translation_floor_mm", t.repeat_translation_floor_m * 1e3},
          {"slip_sigma", t.slip_sigma},
          {"max_rotation_sigma_deg", t.max_rotation_sigma_rad / kRadPerDeg},
          {"max_translation_sigma_mm", t.max_translation_sigma_m * 1e3},
          {"segment_rests", segment_rests}};
}

Verdict verdict_of(const JsonField& field) {
  const std::string text = field.text();
  for (const Verdict v : {Verdict::kPass, Verdict::kWarn, Verdict::kFail})
    if (text == to_string(v)) return v;
  field.refuse(fmt::format("'{}' is not pass, warn or fail", text));
}

PoseResidual residual_of(const JsonField& f) {
  return {f["label"].text(), f["normalised"].number_or_nan(),
          f["rotation_deg"].number_or_nan() * kRadPerDeg, f["position_mm"].number_or_nan() * 1e-3,
          f["outlier"].boolean()};
}

// The covariance holds the 1-sigma the file gives on its diagonal.
MountingEstimate mounting_of(const JsonField& f) {
  MountingEstimate e;
  e.T_S_H = pose_of(f["T_S_H"]);
  const auto rotation = f.optional("sigma_rotation_deg");
  const auto translation = f.optional("sigma_translation_mm");
  if (rotation.has_value() != translation.has_value())
    f.refuse("gives one of sigma_rotation_deg and sigma_translation_mm without the other");
  if (rotation) {
    // Read before the comma initializer: a refusal thrown inside one aborts in Eigen's destructor.
    const Eigen::VectorXd rotation_rad = vector_of(*rotation, 3, 1.0 / kRadPerDeg);
    const Eigen::VectorXd translation_m = vector_of(*translation, 3, 1e3);
    Eigen::Matrix<double, 6, 1> s;
    s << rotation_rad, translation_m;
    e.covariance = s.cwiseAbs2().asDiagonal();
    e.has_covariance = true;
  }
  return e;
}

MountingDifference difference_of(const JsonField& f) {
  MountingDifference d;
  d.rotation_rad = f["rotation_deg"].number_or_nan() * kRadPerDeg;
  d.translation_m = f["translation_mm"].number_or_nan() * 1e-3;
  // Each part read before its comma initializer (see mounting_of).
  const Eigen::VectorXd difference_rad =
      vector_of(f["difference_rotation_deg"], 3, 1.0 / kRadPerDeg);
  const Eigen::VectorXd difference_m = vector_of(f["difference_translation_mm"], 3, 1e3);
  const Eigen::VectorXd sigma_rad =
      vector_of(f["combined_sigma_rotation_deg"], 3, 1.0 / kRadPerDeg);
  const Eigen::VectorXd sigma_m = vector_of(f["combined_sigma_translation_mm"], 3, 1e3);
  d.difference << difference_rad, difference_m;
  d.combined_sigma << sigma_rad, sigma_m;
  // Written as null when infinite (a sigma missing and a difference that is not zero).
  d.normalised = f["normalised_sigma"].is_null() ? std::numeric_limits<double>::infinity()
                                                 : f["normalised_sigma"].number();
  return d;
}

SessionPart part_of(const JsonField& f) {
  SessionPart p;
  p.label = f["label"].text();
  const std::size_t first = f["first_rest"].count(), last = f["last_rest"].count();
  if (first < 1 || last < first)
    f.refuse(fmt::format("rests {}-{} are no range from 1", first, last));
  p.first_rest = first - 1;
  p.last_rest = last - 1;
  p.calibrated = f["calibrated"].boolean();
  if (p.calibrated)
    p.estimate = mounting_of(f["estimate"]);
  else
    p.failure = f["failure"].text();
  return p;
}

std::vector<SessionPart> parts_of(const JsonField& list) {
  std::vector<SessionPart> parts;
  for (std::size_t k = 0; k < list.size(); ++k) parts.push_back(part_of(list[k]));
  return parts;
}

// The segments' comparisons name their segments by label.
std::vector<SegmentComparison> comparisons_of(const JsonField& list,
                                              const std::vector<SessionPart>& segments) {
  const auto index_of = [&](const JsonField& label) {
    const std::string text = label.text();
    for (std::size_t k = 0; k < segments.size(); ++k)
      if (segments[k].label == text) return k;
    label.refuse(fmt::format("no segment is labelled '{}'", text));
  };
  std::vector<SegmentComparison> out;
  for (std::size_t k = 0; k < list.size(); ++k) {
    const JsonField c = list[k];
    out.push_back({index_of(c["earlier"]), index_of(c["later"]), difference_of(c["difference"]),
                   c["slipped"].boolean()});
  }
  return out;
}

MountingThresholds thresholds_of(const JsonField& f) {
  MountingThresholds t;
  t.max_outliers_pass = f["max_outliers_pass"].count();
  t.max_outlier_fraction_warn = f["max_outlier_fraction_warn"].number();
  t.repeat_warn_sigma = f["repeat_warn_sigma"].number();
  t.repeat_fail_sigma = f["repeat_fail_sigma"].number();
  t.repeat_rotation_floor_rad = f["repeat_rotation_floor_deg"].number() * kRadPerDeg;
  t.repeat_translation_floor_m = f["repeat_translation_floor_mm"].number() * 1e-3;
  t.slip_sigma = f["slip_sigma"].number();
  t.max_rotation_sigma_rad = f["max_rotation_sigma_deg"].number() * kRadPerDeg;
  t.max_translation_sigma_m = f["max_translation_sigma_mm"].number() * 1e-3;
  return t;
}

void read_checks(const JsonField& root, MountingValidation& v) {
  v.verdict = verdict_of(root["verdict"]);
  v.reasons = root["reasons"].texts();
  const JsonField checks = root["checks"];
  for (std::size_t k = 0; k < checks.size(); ++k)
    v.checks.push_back(
        {checks[k]["name"].text(), verdict_of(checks[k]["level"]), checks[k]["message"].text()});
}

void read_residuals(const JsonField& root, MountingValidation& v) {
  for (const auto& [key, list] : {std::pair{"rest_residuals", &v.rest_residuals},
                                  {"motion_residuals", &v.motion_residuals}}) {
    const JsonField residuals = root[key];
    for (std::size_t k = 0; k < residuals.size(); ++k) list->push_back(residual_of(residuals[k]));
  }
  v.outliers = root["outliers"].texts();
  v.outlier_count = root["outlier_count"].count();
  const JsonField weak = root["weak_directions"];
  for (std::size_t k = 0; k < weak.size(); ++k) v.weak_directions.push_back(weak_of(weak[k]));
}

}  // namespace

json mounting_report_json(const MountingReport& report, const json& frames_from,
                          const json& inputs) {
  const MountingValidation& v = report.validation;
  json rest_residuals = json::array(), motion_residuals = json::array();
  for (const auto& p : v.rest_residuals) rest_residuals.push_back(residual_json(p));
  for (const auto& p : v.motion_residuals) motion_residuals.push_back(residual_json(p));
  json checks = json::array();
  for (const auto& c : v.checks)
    checks.push_back({{"name", c.name}, {"level", to_string(c.level)}, {"message", c.message}});
  json halves = json::array(), segments = json::array(), comparisons = json::array();
  for (const auto& p : v.halves) halves.push_back(part_json(p));
  for (const auto& p : v.segments) segments.push_back(part_json(p));
  for (const auto& c : v.segment_comparisons)
    comparisons.push_back({{"earlier", v.segments.at(c.earlier).label},
                           {"later", v.segments.at(c.later).label},
                           {"slipped", c.slipped},
                           {"difference", difference_json(c.difference)}});
  json weak = json::array();
  for (const auto& w : v.weak_directions) weak.push_back(weak_json(w));
  return {{kVersionKey, 1},
          {"created_by", report.created_by},
          {"frames_from", frames_from},
          {"verdict", to_string(v.verdict)},
          {"reasons", v.reasons},
          {"checks", checks},
          {"combined", mounting_json(v.combined)},
          {"rest_residuals", rest_residuals},
          {"motion_residuals", motion_residuals},
          {"outliers", v.outliers},
          {"outlier_count", v.outlier_count},
          {"halves", halves},
          {"halves_difference",
           v.halves_difference ? difference_json(*v.halves_difference) : json(nullptr)},
          {"segments", segments},
          {"segment_comparisons", comparisons},
          {"weak_directions", weak},
          {"thresholds", thresholds_json(report.thresholds, report.segment_rests)},
          {"inputs", inputs}};
}

MountingReport read_mounting_report(const std::filesystem::path& file) {
  const JsonDocument document = read_json_document(file);
  document.check_version(kVersionKey, 1, "an imscal mounting_report.json");
  const JsonField root = document.root();
  MountingReport report;
  report.created_by = root["created_by"].text();
  if (const auto from = root.optional("frames_from")) report.frames_from = (*from)["path"].text();
  MountingValidation& v = report.validation;
  read_checks(root, v);
  v.combined = mounting_of(root["combined"]);
  read_residuals(root, v);
  v.halves = parts_of(root["halves"]);
  if (const auto difference = root.optional("halves_difference"))
    v.halves_difference = difference_of(*difference);
  v.segments = parts_of(root["segments"]);
  v.segment_comparisons = comparisons_of(root["segment_comparisons"], v.segments);
  report.thresholds = thresholds_of(root["thresholds"]);
  report.segment_rests = root["thresholds"]["segment_rests"].count();
  return report;
}

}  // namespace imscal::calib
