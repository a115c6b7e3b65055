// Speed of the frame-and-bias bundle (goal: a 10-minute record at 1 kHz calibrated in
// < 5 s on one core). The record is made once, outside the timed loop: the 14 poses of
// datasets/programs/mounting.yaml cycled for 10 minutes (6 s rests, 3 s quintic joint moves, a
// kinematic record as in tests/calib/frame_calibration_scenes.hpp), the navigation-grade IMS at
// 1 kHz with its noise; the initial time offset by cross-correlation (also outside). Timed:
// calibrate_frames (cutting, preintegration, initial values, two solves, covariance).
// Beside it, the whole session as `imscal calibrate` runs it (calib::calibrate_session: rests,
// clock offset, bundle, halves and segments, joint errors) on the shipped 70 s campaign
// (datasets/campaign/), its files read once outside the timed loop.
// The whole `imscal calibrate` command on the same campaign, as a child process (files and
// outputs included).
#include <benchmark/benchmark.h>

#include <chrono>
#include <filesystem>

#include "calib/calibration_session.hpp"
#include "calib/calibration_session_inputs.hpp"
#include "calib/frame_calibration.hpp"
#include "calib/time_offset.hpp"
#include "core/subprocess.hpp"
#include "robot/robot_description.hpp"
#include "tests/calib/frame_calibration_scenes.hpp"

namespace {

using imscal::calib::JointVector;

JointVector deg(double a1, double a2, double a3, double a4, double a5, double a6) {
  JointVector q;
  q << a1, a2, a3, a4, a5, a6;
  return q * M_PI / 180.0;
}

struct Record {
  imscal::test_support::FrameScene scene;
  imscal::calib::FrameCalibrationInput input;
};

const Record& ten_minute_record() {
  static const Record record = [] {
    Record r;
    const std::filesystem::path root(IMSCAL_SOURCE_DIR);
    const auto robot = imscal::calib::load_robot_description(root / "datasets/robots/kr16.yaml");
    const auto spec =
        imscal::ims::load_sensor_spec(root / "datasets/sensors/navigation-grade.yaml");
    const std::vector<JointVector> program = {
        deg(0, -90, 90, 0, 45, 0),        deg(0, -90, 90, 0, 45, 90),
        deg(0, -90, 90, 0, 45, -90),      deg(0, -90, 90, 0, -45, 0),
        deg(0, -90, 90, 90, 45, 0),       deg(0, -90, 90, -90, 45, 0),
        deg(30, -80, 100, 0, 90, 0),      deg(-30, -100, 80, 45, 100, 45),
        deg(45, -60, 110, -120, 60, 180), deg(-45, -110, 70, 120, -60, -135),
        deg(20, -70, 60, 180, 90, 90),    deg(-20, -95, 120, -45, -100, 30),
        deg(0, -80, 100, 90, 90, 90),     deg(10, -90, 90, 0, 45, 0)};
    std::vector<JointVector> poses;
    for (int i = 0; i < 67; ++i) poses.push_back(program[i % program.size()]);  // 67 x 9 s
    r.scene.kinematics = robot.kinematics;
    r.scene.T_W_R =
        Eigen::Translation3d(2.0, 1.0, 0.0) * Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitZ());
    r.scene.T_H_S = robot.tool.T_H_T;
    imscal::test_support::make_kinematic_motion(r.scene, poses, 6.0, 3.0);
    imscal::test_support::synthesize_scene_imu(r.scene);
    imscal::test_support::corrupt_scene_imu(r.scene, spec, 1);
    r.input =
        imscal::test_support::frame_input(r.scene, imscal::test_support::noise_model_of(spec));
    const auto robot_rate = imscal::calib::flange_rate_magnitude(
        r.input.kinematics, r.input.robot.t_robot_s, r.input.robot.q_rad);
    const auto& first = r.scene.imu.samples[2000];  // inside the first rest
    const auto ims_rate = imscal::calib::ims_rate_magnitude(
        r.scene.imu, Eigen::Vector3d(first.gyro / r.scene.imu.nominal_dt_s));
    r.input.time_offset_initial_s =
        imscal::calib::estimate_time_offset(robot_rate, ims_rate).offset_s;
    return r;
  }();
  return record;
}

void BM_CalibrateTenMinutes1kHz(benchmark::State& state) {
  const Record& record = ten_minute_record();
  Record copy = record;  // the input points at the scene's IMS series
  copy.input.imu = &copy.scene.imu;
  bool converged = false;
  for (auto _ : state) {
    const auto result = imscal::calib::calibrate_frames(copy.input);
    converged = result.converged;
    benchmark::DoNotOptimize(result.T_S_H);
  }
  state.counters["record_s"] = copy.scene.t_robot_s.back();
  state.counters["imu_samples"] = static_cast<double>(copy.scene.imu.samples.size());
  state.counters["rests"] = static_cast<double>(copy.input.rests.size());
  state.counters["converged"] = converged ? 1.0 : 0.0;
}
BENCHMARK(BM_CalibrateTenMinutes1kHz)->Unit(benchmark::kSecond)->Iterations(1)->UseRealTime();

void BM_CalibrateSessionCampaign(benchmark::State& state) {
  const std::filesystem::path campaign =
      std::filesystem::path(IMSCAL_SOURCE_DIR) / "datasets" / "campaign";
  imscal::calib::SessionFiles files;
  files.imu = (campaign / "imu.csv").string();
  files.robot_log = (campaign / "robot.csv").string();
  files.config = (campaign / "calibrate.yaml").string();
  const imscal::calib::LoadedSession loaded = imscal::calib::read_session_inputs(files);
  std::size_t rests = 0;
  for (auto _ : state) {
    const auto session = imscal::calib::calibrate_session(loaded.inputs, loaded.options);
    rests = session.rests.rests.size();
    benchmark::DoNotOptimize(session.frames.T_S_H);
  }
  state.counters["rests"] = static_cast<double>(rests);
}
BENCHMARK(BM_CalibrateSessionCampaign)->Unit(benchmark::kSecond)->Iterations(1)->UseRealTime();

// The whole command as a user meets it on the shipped campaign (70 s at 1 kHz): `imscal
// calibrate` as a child process, reading the files, the time offset, the bundle, the joint errors
// and the outputs, wall time. calibrate_frames above is only its bundle.
void BM_CalibrateCommandCampaign(benchmark::State& state) {
  const std::filesystem::path campaign =
      std::filesystem::path(IMSCAL_SOURCE_DIR) / "datasets/campaign";
  const std::filesystem::path out =
      std::filesystem::temp_directory_path() / "imscal-bench-calibrate";
  imscal::SubprocessOptions options;
  options.timeout_s = 600.0;
  for (auto _ : state) {
    std::filesystem::remove_all(out);
    const auto start = std::chrono::steady_clock::now();
    const auto result = imscal::run_subprocess(
        {IMSCAL_BINARY, "calibrate", "--imu", (campaign / "imu.csv").string(), "--robot-log",
         (campaign / "robot.csv").string(), "--config", (campaign / "calibrate.yaml").string(),
         "--out", out.string()},
        options);
    state.SetIterationTime(
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    if (result.exit_code != 0)
      state.SkipWithError(("imscal calibrate failed:\n" + result.output).c_str());
  }
  std::filesystem::remove_all(out);
}
BENCHMARK(BM_CalibrateCommandCampaign)->UseManualTime()->Unit(benchmark::kSecond)->Iterations(3);

}  // namespace

BENCHMARK_MAIN();
