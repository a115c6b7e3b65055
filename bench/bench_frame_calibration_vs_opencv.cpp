// imscal's frame bundle against OpenCV's closed-form peers on the same simulated mounting data
// (goal: "imscal's rotation and translation errors at least 3x smaller"). Per seed: the
// mounting program (tests/data/scenarios/mounting-rigid.yaml, planned joint motion, rigid arm),
// random base heading / IMS mount / clock offset, the navigation-grade IMS with its turn-on
// biases and noise (as tests/calib/test_frame_calibration.cpp). The peers get the rest poses:
// forward kinematics T_R_H_i and the IMS poses T_W_S_i of the zero-bias preintegration chain
// from a coarse alignment at rest 1 (calib/frame_initialisation.hpp; the bundle's own start).
// Errors: T_R_W in the W-origin convention of calib/frame_calibration.hpp (rotation incl. the
// heading), T_S_H. Prints the table of means (run with --benchmark_filter=none to skip timing).
#include <benchmark/benchmark.h>
#include <fmt/format.h>

#include <cstdio>
#include <filesystem>
#include <random>

#include "bench/hand_eye_comparison.hpp"
#include "bench/opencv_hand_eye.hpp"
#include "calib/frame_calibration.hpp"
#include "calib/frame_initialisation.hpp"
#include "calib/frame_measurements.hpp"
#include "calib/time_offset.hpp"
#include "sim/motion_planner.hpp"
#include "sim/motion_program.hpp"
#include "sim/scenario.hpp"
#include "tests/calib/frame_calibration_scenes.hpp"

namespace {

using namespace imscal;

struct SeedData {
  test_support::FrameScene scene;
  calib::FrameCalibrationInput input;
  Eigen::Isometry3d T_R_W_true;  // W-origin convention
  std::vector<Eigen::Isometry3d> T_R_H, T_W_S;
};

SeedData make_seed(std::uint64_t seed) {
  const sim::Scenario scenario = sim::load_scenario(std::filesystem::path(IMSCAL_SOURCE_DIR) /
                                                    "tests/data/scenarios/mounting-rigid.yaml");
  const calib::RobotDescription robot = sim::load_plant_robot(scenario);
  const ims::SensorSpec spec = ims::load_sensor_spec(scenario.sensor_file);
  const sim::DesiredJointPath path =
      sim::plan_motion(robot, sim::load_motion_program(scenario.program_file));
  SeedData d;
  std::mt19937_64 rng(seed * 7919 + 17);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  std::normal_distribution<double> normal(0.0, 1.0);
  auto& scene = d.scene;
  scene.kinematics = robot.kinematics;
  scene.site = scenario.site;
  scene.T_W_R = scenario.T_W_R;
  scene.T_W_R.linear() =
      Eigen::AngleAxisd(M_PI * uniform(rng), Eigen::Vector3d::UnitZ()) * scenario.T_W_R.linear();
  Eigen::Vector3d rotation, translation;
  for (int k = 0; k < 3; ++k) rotation[k] = normal(rng) * scenario.mount_random_rotation_sigma_rad;
  for (int k = 0; k < 3; ++k) translation[k] = normal(rng) * scenario.mount_random_position_sigma_m;
  Eigen::Isometry3d perturbation = Eigen::Isometry3d::Identity();
  perturbation.linear() = ims::quat_exp<double>(rotation).toRotationMatrix();
  perturbation.translation() = translation;
  scene.T_H_S = robot.tool.T_H_T * scenario.mount_offset * perturbation;
  scene.clock_offset_s = 0.03 * uniform(rng);
  for (const auto& s : path.samples) {
    scene.t_robot_s.push_back(s.t_s);
    scene.q_rad.push_back(s.q_rad);
  }
  for (const auto& seg : path.segments) {
    if (seg.kind != sim::SegmentKind::kRest) continue;
    scene.rest_begin_s.push_back(seg.begin_s);
    scene.rest_end_s.push_back(seg.end_s);
    const auto mid =
        static_cast<std::size_t>(std::lround(0.5 * (seg.begin_s + seg.end_s) / path.cycle_s));
    scene.rest_q_rad.push_back(path.samples[std::min(mid, path.samples.size() - 1)].q_rad);
  }
  test_support::synthesize_scene_imu(scene);
  test_support::corrupt_scene_imu(scene, spec, seed);
  d.input = test_support::frame_input(scene, test_support::noise_model_of(spec), 0.5, 1);
  d.T_R_W_true = calib::frame_calibration_truth_convention(
      scene.T_R_W(), scene.T_S_H(), scene.kinematics, scene.rest_q_rad.front());
  return d;
}

void fill_rest_poses(SeedData& d) {
  d.input.imu = &d.scene.imu;
  std::vector<calib::RestWindow> rests;
  for (const auto& r : d.input.rests) {
    rests.push_back(
        calib::cut_rest_window(d.scene.imu, r.begin_ims_s, r.end_ims_s, r.label, "bench"));
  }
  const auto motions = calib::integrate_motions(d.scene.imu, rests, calib::ImuBiases{});
  const auto init =
      calib::initial_frame_values(d.input, rests, motions, ims::EarthModel(d.input.site));
  d.T_R_H = init.T_R_H_rest;
  d.T_W_S = init.T_W_S_rest;
  // Automatic initial time offset (cross-correlation), as the bundle's caller would.
  const auto robot_rate = calib::flange_rate_magnitude(d.input.kinematics, d.input.robot.t_robot_s,
                                                       d.input.robot.q_rad);
  const auto ims_rate =
      calib::ims_rate_magnitude(d.scene.imu, Eigen::Vector3d(rests[0].mean_rate_rad_s));
  d.input.time_offset_initial_s = calib::estimate_time_offset(robot_rate, ims_rate).offset_s;
}

void add(bench::HandEyeComparisonRow& row, const bench::HandEyeEstimate& e, const SeedData& d) {
  const auto z = bench::frame_error(e.T_R_W, d.T_R_W_true);
  const auto x = bench::frame_error(e.T_S_H, d.scene.T_S_H());
  row.Z_rotation_deg += z.rotation_rad * 180.0 / M_PI;
  row.Z_translation_mm += z.translation_m * 1e3;
  row.X_rotation_deg += x.rotation_rad * 180.0 / M_PI;
  row.X_translation_mm += x.translation_m * 1e3;
  ++row.runs;
}

void print_comparison(int seeds) {
  using Estimator = std::function<bench::HandEyeEstimate(SeedData&)>;
  const std::vector<std::pair<std::string, Estimator>> methods = {
      {"imscal bundle (calibrate_frames)",
       [](SeedData& d) {
         const auto r = calib::calibrate_frames(d.input);
         return bench::HandEyeEstimate{r.T_R_W, r.T_S_H};
       }},
      {"imscal closed form (hand_eye.hpp)",
       [](SeedData& d) {
         const auto r = calib::solve_robot_world_hand_eye(d.T_R_H, d.T_W_S);
         return bench::HandEyeEstimate{r.T_R_W, r.T_S_H};
       }},
      {"OpenCV RobotWorldHandEye SHAH",
       [](SeedData& d) {
         return bench::opencv_robot_world_hand_eye(d.T_R_H, d.T_W_S,
                                                   cv::CALIB_ROBOT_WORLD_HAND_EYE_SHAH);
       }},
      {"OpenCV RobotWorldHandEye LI",
       [](SeedData& d) {
         return bench::opencv_robot_world_hand_eye(d.T_R_H, d.T_W_S,
                                                   cv::CALIB_ROBOT_WORLD_HAND_EYE_LI);
       }},
      {"OpenCV HandEye TSAI",
       [](SeedData& d) {
         return bench::opencv_hand_eye(d.T_R_H, d.T_W_S, cv::CALIB_HAND_EYE_TSAI);
       }},
      {"OpenCV HandEye PARK",
       [](SeedData& d) {
         return bench::opencv_hand_eye(d.T_R_H, d.T_W_S, cv::CALIB_HAND_EYE_PARK);
       }},
      {"OpenCV HandEye DANIILIDIS", [](SeedData& d) {
         return bench::opencv_hand_eye(d.T_R_H, d.T_W_S, cv::CALIB_HAND_EYE_DANIILIDIS);
       }}};
  std::vector<bench::HandEyeComparisonRow> rows(methods.size());
  for (std::size_t m = 0; m < methods.size(); ++m) rows[m].name = methods[m].first;
  for (int s = 1; s <= seeds; ++s) {
    SeedData d = make_seed(static_cast<std::uint64_t>(s));
    fill_rest_poses(d);
    for (std::size_t m = 0; m < methods.size(); ++m) {
      try {
        add(rows[m], methods[m].second(d), d);
      } catch (const std::exception&) {
        ++rows[m].runs;
        ++rows[m].failures;
      }
    }
  }
  for (auto& r : rows) {
    const int ok = r.runs - r.failures;
    if (ok == 0) continue;
    r.Z_rotation_deg /= ok;
    r.Z_translation_mm /= ok;
    r.X_rotation_deg /= ok;
    r.X_translation_mm /= ok;
  }
  std::printf(
      "Frame calibration on simulated mounting data, %d seeds (means; Z = T_R_W in the "
      "W-origin convention, X = T_S_H):\n%s",
      seeds, bench::format_hand_eye_table(rows).c_str());
}

void BM_BundleOneSeed(benchmark::State& state) {
  SeedData d = make_seed(1);
  fill_rest_poses(d);
  for (auto _ : state) benchmark::DoNotOptimize(calib::calibrate_frames(d.input).T_S_H);
}
BENCHMARK(BM_BundleOneSeed)->Unit(benchmark::kMillisecond)->Iterations(1);

}  // namespace

int main(int argc, char** argv) {
  print_comparison(5);
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
