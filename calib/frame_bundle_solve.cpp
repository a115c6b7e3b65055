// Solving the frame-and-bias bundle (calib/frame_bundle.hpp): the problem of one stage and the
// two solves (the second with the rate-window sigma from the first one's residuals).
#include <algorithm>
#include <cmath>

#include "calib/frame_bundle.hpp"

namespace imscal::calib {

void build_frame_stage(FrameBundle& b, FrameStage& stage, const ImuBiases& linearisation) {
  ceres::Problem::Options problem_options;
  stage.problem = std::make_unique<ceres::Problem>(problem_options);
  ceres::Problem& problem = *stage.problem;
  stage.motions = integrate_motions(*b.input.imu, b.rests, linearisation);
  add_frame_and_bias_blocks(b, problem);
  add_known_frames(b, problem);
  add_heading_reference(b, problem);
  add_acc_bias_drift(b, problem);
  add_scale_factors(b, problem);
  add_deflection_scale(b, problem);
  add_joint_deviations(b, problem);
  // Absolute positions of the rests and their creep, from the current estimate.
  const std::vector<Eigen::Vector3d> p_W = rest_positions_W(b);
  const std::vector<RestCreep> creep = rest_creeps(b);
  add_rest_residuals(b, stage, p_W, creep);
  add_motion_residuals(b, stage, p_W, creep);
  add_time_offset(b, stage);
}

void solve_frame_stage(const FrameBundle& b, FrameStage& stage) {
  const FrameCalibrationOptions& options = b.options;
  ceres::Solver::Options solver;
  solver.linear_solver_type = options.sparse ? ceres::SPARSE_NORMAL_CHOLESKY : ceres::DENSE_QR;
  solver.max_num_iterations = options.max_iterations;
  solver.minimizer_progress_to_stdout = options.report_progress;
  solver.function_tolerance = 1e-15;
  solver.gradient_tolerance = 1e-15;
  solver.parameter_tolerance = 1e-14;
  solver.num_threads = 1;
  ceres::Solve(solver, stage.problem.get(), &stage.summary);
}

std::pair<FrameStage, FrameStage> solve_frame_bundle(FrameBundle& b) {
  FrameStage first;
  build_frame_stage(b, first, ImuBiases{});
  solve_frame_stage(b, first);
  // Window sigma from the data: RMS of the first solve's unweighted rate residuals.
  if (!b.rate_windows.empty()) {
    double sum_sq = 0.0;
    for (const RateWindow& w : b.rate_windows) {
      const RateResidual f = rate_functor(b, w);
      double r[3];
      f(b.x.dt, b.x.link_share, r);
      for (double v : r) sum_sq += (v * f.sigma) * (v * f.sigma);
    }
    const double rms = std::sqrt(sum_sq / (3.0 * static_cast<double>(b.rate_windows.size())));
    b.rate_sigma = std::max(rms, b.rate_window_noise);
  }
  FrameStage final_stage;
  build_frame_stage(b, final_stage, b.x.biases());
  solve_frame_stage(b, final_stage);
  return {std::move(first), std::move(final_stage)};
}

}  // namespace imscal::calib
