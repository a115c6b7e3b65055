#include "ims/alignment_session.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <cmath>
#include <memory>
#include <sstream>
#include <vector>

#include "core/input_error.hpp"
#include "core/units.hpp"
#include "ims/imu_file.hpp"

namespace imscal::ims {

namespace {

constexpr double kDegPerHour = kRadPerDeg / 3600.0;

Site parse_site(const std::string& text) {
  Site site;
  double values[3];
  std::istringstream in(text);
  for (int i = 0; i < 3; ++i) {
    std::string token;
    if (!std::getline(in, token, ',')) {
      throw InputError("<command line>", 0, "--site",
                       "expected LAT,LON,H (deg, deg, m), got '" + text + "'");
    }
    try {
      std::size_t used = 0;
      values[i] = std::stod(token, &used);
      if (used != token.size() || !std::isfinite(values[i])) throw std::invalid_argument(token);
    } catch (const std::exception&) {
      throw InputError("<command line>", 0, "--site",
                       "'" + token + "' is not a number (expected LAT,LON,H)");
    }
  }
  site.latitude_deg = values[0];
  site.longitude_deg = values[1];
  site.height_m = values[2];
  return site;
}

std::string summary_line(const std::string& label, const CoarseAlignment& a) {
  return fmt::format(
      "{:<10} t_ref {:9.2f} s  heading {:9.4f} +- {:.4f} deg  (PSINS yaw {:9.4f})  pitch {:8.4f} "
      "+- {:.4f} deg  roll {:8.4f} +- {:.4f} deg\n",
      label, a.t_ref_s, a.angles.heading_rad / kRadPerDeg, a.sigma_heading_rad / kRadPerDeg,
      a.angles.yaw_rad / kRadPerDeg, a.angles.pitch_rad / kRadPerDeg,
      a.sigma_pitch_rad / kRadPerDeg, a.angles.roll_rad / kRadPerDeg,
      a.sigma_roll_rad / kRadPerDeg);
}

// The site from the options, else from the file.
std::pair<Site, std::string> choose_site(const AlignmentSessionOptions& args,
                                         const ImuSeries& series) {
  if (!args.site.empty()) return {parse_site(args.site), "command line"};
  if (series.site) return {*series.site, "input file"};
  throw InputError(args.input, 0, "site",
                   "the file names no site; give --site LAT,LON,H (needed for the Earth "
                   "rate and gravity)");
}

// The samples of the options' interval; InputError when it is not inside the record.
SampleRange interval_of(const AlignmentSessionOptions& args, const ImuSeries& series) {
  const auto& samples = series.samples;
  const double dt0 = samples.size() > 1 ? samples[1].t_s - samples[0].t_s : series.nominal_dt_s;
  const double record_start = samples.front().t_s - dt0;
  const double record_end = samples.back().t_s;
  const double start = record_start + args.start_s;
  const double duration = args.duration_s ? *args.duration_s : record_end - start;
  if (args.start_s < 0.0 || !(duration > 0.0) || start + duration > record_end + 0.5 * dt0) {
    throw InputError(
        "<command line>", 0, "--start-s/--duration-s",
        fmt::format("interval [{}, {}] s after the record start is not inside the record "
                    "(0 .. {} s)",
                    args.start_s, args.start_s + duration, record_end - record_start));
  }
  return samples_in_interval(series, start, duration);
}

// The whole interval's checks: |f| against gravity, the horizontal Earth rate seen.
std::string interval_text(const CoarseAlignment& whole) {
  std::string text = summary_line("interval", whole);
  const double rate_ratio =
      whole.earth_rate_horizontal_rad_s / whole.expected_earth_rate_horizontal_rad_s;
  text += fmt::format(
      "           |f| {:.5f} m/s^2 (normal gravity {:.5f}); horizontal Earth rate {:.3f} deg/h "
      "(expected {:.3f}); blocks used {} of {} ({:.1f} s each)\n",
      whole.specific_force_m_s2, whole.expected_gravity_m_s2,
      whole.earth_rate_horizontal_rad_s / kDegPerHour,
      whole.expected_earth_rate_horizontal_rad_s / kDegPerHour, whole.blocks_used,
      whole.blocks_used + whole.blocks_rejected, whole.block_duration_s);
  if (rate_ratio < 0.8 || rate_ratio > 1.25) {
    spdlog::warn(
        "the gyros see {:.0f} % of the horizontal Earth rate: the heading is not "
        "reliable (gyros not good enough to gyrocompass, or not at rest)",
        100.0 * rate_ratio);
  }
  return text;
}

// The windows, and their spread when there are two or more, into the document and the text.
void add_windows(const std::vector<CoarseAlignment>& windows, double window_s, nlohmann::json& out,
                 std::string& text) {
  nlohmann::json list = nlohmann::json::array();
  for (std::size_t k = 0; k < windows.size(); ++k) {
    list.push_back(alignment_json(windows[k]));
    text += summary_line(fmt::format("window {}", k), windows[k]);
  }
  out["window_s"] = window_s;
  out["windows"] = list;
  if (windows.size() < 2) return;
  nlohmann::json spread;
  const std::pair<const char*, AngleKind> kinds[] = {
      {"roll", AngleKind::kRoll}, {"pitch", AngleKind::kPitch}, {"heading", AngleKind::kHeading}};
  for (const auto& [name, kind] : kinds) {
    const AngleSpread s = angle_spread(windows, kind);
    spread[std::string(name) + "_mean_deg"] = s.mean_rad / kRadPerDeg;
    spread[std::string(name) + "_std_deg"] = s.std_rad / kRadPerDeg;
    spread[std::string(name) + "_max_minus_min_deg"] = (s.max_rad - s.min_rad) / kRadPerDeg;
  }
  out["window_spread"] = spread;
  text += fmt::format(
      "spread over {} windows: heading std {:.4f} deg (max-min {:.4f}), pitch "
      "std {:.4f} deg, roll std {:.4f} deg\n",
      windows.size(), spread["heading_std_deg"].get<double>(),
      spread["heading_max_minus_min_deg"].get<double>(), spread["pitch_std_deg"].get<double>(),
      spread["roll_std_deg"].get<double>());
}

}  // namespace

nlohmann::json alignment_json(const CoarseAlignment& a) {
  nlohmann::json j;
  j["t_ref_s"] = a.t_ref_s;
  j["start_s"] = a.start_s;
  j["end_s"] = a.end_s;
  j["duration_s"] = a.end_s - a.start_s;
  j["first_sample"] = a.first_sample;
  j["sample_count"] = a.sample_count;
  j["roll_deg"] = a.angles.roll_rad / kRadPerDeg;
  j["pitch_deg"] = a.angles.pitch_rad / kRadPerDeg;
  j["heading_cw_from_north_deg"] = a.angles.heading_rad / kRadPerDeg;
  j["yaw_psins_ccw_from_north_deg"] = a.angles.yaw_rad / kRadPerDeg;
  j["sigma_roll_deg"] = a.sigma_roll_rad / kRadPerDeg;
  j["sigma_pitch_deg"] = a.sigma_pitch_rad / kRadPerDeg;
  j["sigma_heading_deg"] = a.sigma_heading_rad / kRadPerDeg;
  j["q_W_S"] = {{"w", a.q_W_S.w()}, {"x", a.q_W_S.x()}, {"y", a.q_W_S.y()}, {"z", a.q_W_S.z()}};
  j["specific_force_m_s2"] = a.specific_force_m_s2;
  j["expected_gravity_m_s2"] = a.expected_gravity_m_s2;
  j["earth_rate_horizontal_deg_per_h"] = a.earth_rate_horizontal_rad_s / kDegPerHour;
  j["expected_earth_rate_horizontal_deg_per_h"] =
      a.expected_earth_rate_horizontal_rad_s / kDegPerHour;
  j["blocks_used"] = a.blocks_used;
  j["blocks_rejected"] = a.blocks_rejected;
  j["block_duration_s"] = a.block_duration_s;
  return j;
}

AlignmentSession align_session(const AlignmentSessionOptions& args) {
  const ImuSeries series = read_imu_file(args.input);
  const auto [site, site_source] = choose_site(args, series);
  std::unique_ptr<EarthModel> earth;
  try {
    earth = std::make_unique<EarthModel>(site);
  } catch (const std::invalid_argument& e) {
    throw InputError("<command line>", 0, "--site", e.what());
  }
  const SampleRange range = interval_of(args, series);
  CoarseAlignmentOptions options;
  options.block_count = args.block_count;
  CoarseAlignment whole;
  std::vector<CoarseAlignment> windows;
  try {
    whole = align_at_rest(series, range, *earth, options);
    if (args.window_s) windows = align_windows(series, range, *args.window_s, *earth, options);
  } catch (const std::invalid_argument& e) {
    throw InputError("<command line>", 0, "--start-s/--duration-s/--window-s", e.what());
  }
  AlignmentSession r;
  nlohmann::json& out = r.document;
  out["input"] = args.input;
  out["samples_in_file"] = series.samples.size();
  out["site"] = {{"latitude_deg", site.latitude_deg},
                 {"longitude_deg", site.longitude_deg},
                 {"height_m", site.height_m},
                 {"from", site_source}};
  out["conventions"] =
      "W = ENU; sensor axes as in the file (PSINS: X right, Y forward, Z up); R_W_S = Rz(yaw) "
      "Rx(pitch) Ry(roll); heading clockwise from North of +Y = -yaw; q_W_S maps S into W; "
      "attitude at t_ref_s (middle of the interval); sigmas are 1-sigma from data noise only "
      "(accelerometer biases and horizontal gyro biases are not observable at rest)";
  out["method"] =
      "inertial-frame gyrocompassing: gyro-tracked specific force, line fit over "
      "blocks, white + random-walk noise model from the residuals";
  out["alignment"] = alignment_json(whole);
  r.summary = interval_text(whole);
  if (args.window_s) add_windows(windows, *args.window_s, out, r.summary);
  return r;
}

}  // namespace imscal::ims
