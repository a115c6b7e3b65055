// Robot-world/hand-eye initial values: accuracy table against OpenCV's solvers (printed before the
// timings) and the speed of each solver on one pose set.
//
// Accuracy: mean rotation error [deg] and translation error [mm] of T_R_W (Z) and T_S_H (X) over
// 50 random seeds (random true frames, 20 random KR 16 rest poses, IMS attitude noise 0.001 deg
// and position noise 0.02 mm per axis: a navigation-grade IMS after ZUPT smoothing). This is the
// baseline the full Ceres calibration has to beat by 3x (its goal); the harness is
// bench/hand_eye_comparison.hpp and takes any estimator.
//
// Run: build-<name>/bench/bench_hand_eye   (add --benchmark_filter=none for the table only)
#include <benchmark/benchmark.h>
#include <fmt/format.h>

#include "bench/hand_eye_comparison.hpp"
#include "bench/opencv_hand_eye.hpp"
#include "calib/hand_eye.hpp"
#include "robot/robot_description.hpp"

namespace {

using imscal::bench::HandEyeEstimate;
using imscal::bench::HandEyeEstimator;

const imscal::calib::KinematicModel& kr16() {
  static const imscal::calib::RobotDescription robot =
      imscal::calib::load_robot_description(IMSCAL_SOURCE_DIR "/datasets/robots/kr16.yaml");
  return robot.kinematics;
}

HandEyeEstimate imscal_closed_form(const std::vector<Eigen::Isometry3d>& T_R_H,
                                   const std::vector<Eigen::Isometry3d>& T_W_S) {
  const auto result = imscal::calib::solve_robot_world_hand_eye(T_R_H, T_W_S);
  return {result.T_R_W, result.T_S_H};
}

// Steps 1-3 only (rotations first, then translations), without the joint weighted refinement.
HandEyeEstimate imscal_separable(const std::vector<Eigen::Isometry3d>& T_R_H,
                                 const std::vector<Eigen::Isometry3d>& T_W_S) {
  imscal::calib::HandEyeOptions options;
  options.joint_refinement = false;
  const auto result = imscal::calib::solve_robot_world_hand_eye(T_R_H, T_W_S, options);
  return {result.T_R_W, result.T_S_H};
}

std::vector<std::pair<std::string, HandEyeEstimator>> estimators() {
  using imscal::bench::opencv_hand_eye;
  using imscal::bench::opencv_robot_world_hand_eye;
  return {
      {"imscal (closed form + weighted GN)", imscal_closed_form},
      {"imscal closed form only", imscal_separable},
      {"OpenCV RWHE SHAH",
       [](const auto& a, const auto& b) {
         return opencv_robot_world_hand_eye(a, b, cv::CALIB_ROBOT_WORLD_HAND_EYE_SHAH);
       }},
      {"OpenCV RWHE LI",
       [](const auto& a, const auto& b) {
         return opencv_robot_world_hand_eye(a, b, cv::CALIB_ROBOT_WORLD_HAND_EYE_LI);
       }},
      {"OpenCV HandEye TSAI (+Z mean)",
       [](const auto& a, const auto& b) { return opencv_hand_eye(a, b, cv::CALIB_HAND_EYE_TSAI); }},
      {"OpenCV HandEye PARK (+Z mean)",
       [](const auto& a, const auto& b) { return opencv_hand_eye(a, b, cv::CALIB_HAND_EYE_PARK); }},
      {"OpenCV HandEye DANIILIDIS (+Z mean)",
       [](const auto& a, const auto& b) {
         return opencv_hand_eye(a, b, cv::CALIB_HAND_EYE_DANIILIDIS);
       }},
  };
}

void print_accuracy_table(const std::string& title,
                          const imscal::bench::HandEyeScenarioSpec& spec) {
  constexpr int kSeeds = 50;
  std::vector<imscal::bench::HandEyeComparisonRow> rows;
  for (const auto& [name, estimator] : estimators()) {
    rows.push_back(imscal::bench::run_hand_eye_comparison(name, estimator, kr16(), spec, kSeeds));
  }
  fmt::print(
      "Hand-eye accuracy, {}: mean over {} seeds, {} KR 16 rest poses (joints uniform in {:.0f} % "
      "of their ranges), IMS noise {:.4f} deg / {:.3f} mm per axis; fail = threw or rotation "
      "error > 1 deg (left out of the means)\n{}\n",
      title, kSeeds, spec.pose_count, spec.joint_range_fraction * 100.0,
      spec.attitude_sigma_rad * 180.0 / M_PI, spec.position_sigma_m * 1e3,
      imscal::bench::format_hand_eye_table(rows));
}

void BM_HandEye(benchmark::State& state, HandEyeEstimator estimator) {
  const imscal::bench::HandEyeScenarioSpec spec;
  const auto scenario = imscal::bench::make_hand_eye_scenario(kr16(), 1, spec);
  for (auto _ : state) benchmark::DoNotOptimize(estimator(scenario.T_R_H, scenario.T_W_S));
}

}  // namespace

int main(int argc, char** argv) {
  imscal::bench::HandEyeScenarioSpec wide;  // defaults: 20 poses, 0.001 deg, 0.02 mm, 80 %
  print_accuracy_table("wide pose set", wide);
  imscal::bench::HandEyeScenarioSpec moderate = wide;
  moderate.joint_range_fraction = 0.3;  // relative rotations mostly below ~120 deg
  print_accuracy_table("moderate pose set", moderate);
  for (const auto& [name, estimator] : estimators()) {
    benchmark::RegisterBenchmark(("BM_HandEye/" + name).c_str(), BM_HandEye, estimator);
  }
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
