// `imscal mechanize`: strapdown mechanization of a raw IMS record (ims/mechanize_session.hpp)
// into the trajectory of the sensor frame S in W, written as DIR/trajectory.csv and
// DIR/trajectory.tum (ims/nav_trajectory_io.hpp), both or neither.
//
// The initial attitude comes either from the command line (--initial-attitude, angles as in
// ims/coarse_alignment.hpp) or from a coarse alignment over the first seconds of the record,
// which must then be at rest (--align-s). Position and velocity start at zero.
#include <filesystem>
#include <iostream>
#include <memory>

#include "core/input_error.hpp"
#include "core/output_folder.hpp"
#include "ims/mechanize_session.hpp"
#include "ims/nav_trajectory_io.hpp"
#include "tools/command_registry.hpp"

namespace {

namespace fs = std::filesystem;
namespace ims = imscal::ims;

struct MechanizeArgs {
  ims::MechanizeSessionOptions session;
  std::string out_dir;
  bool force = false;
};

// Both outputs, refused before any work when they exist and --force is not given.
struct Outputs {
  fs::path csv;
  fs::path tum;
};

Outputs check_outputs(const MechanizeArgs& args) {
  const fs::path dir(args.out_dir);
  Outputs o{dir / "trajectory.csv", dir / "trajectory.tum"};
  if (!args.force) {
    for (const fs::path& f : {o.csv, o.tum}) {
      if (fs::exists(f)) {
        throw imscal::InputError("<command line>", 0, "--out",
                                 f.string() + " exists; give --force to overwrite it");
      }
    }
  }
  return o;
}

void run(const MechanizeArgs& args) {
  const Outputs o = check_outputs(args);
  const ims::MechanizedTrajectory trajectory = ims::mechanize_session(args.session);
  // Both or neither: staged together and published together.
  const fs::path dir = o.csv.parent_path().empty() ? fs::path(".") : o.csv.parent_path();
  imscal::OutputFolder folder(dir, {o.csv.filename(), o.tum.filename()},
                              args.force ? imscal::Overwrite::kAllow : imscal::Overwrite::kRefuse);
  ims::write_trajectory_csv(folder.staged(o.csv.filename()), trajectory.states,
                            trajectory.sigmas ? &*trajectory.sigmas : nullptr,
                            imscal::Overwrite::kAllow);
  ims::write_trajectory_tum(folder.staged(o.tum.filename()), trajectory.states,
                            imscal::Overwrite::kAllow);
  folder.commit();
  std::cout << trajectory.summary << "written: " << o.csv.string()
            << "\nwritten: " << o.tum.string() << "\n";
}

imscal::tools::CommandRegistration registration{
    "mechanize",
    "Strapdown mechanization of an IMS record into a trajectory (trajectory.csv, .tum)",
    [](CLI::App& sub) {
      auto args = std::make_shared<MechanizeArgs>();
      sub.add_option("--input", args->session.input, "Raw IMS file (.csv, .imsb, .imu PSINS)")
          ->required();
      sub.add_option("--out", args->out_dir, "Output folder (created if missing)")->required();
      auto* attitude = sub.add_option(
          "--initial-attitude", args->session.initial_attitude,
          "ROLL,PITCH,HEADING in deg (heading clockwise from North, ims/coarse_alignment.hpp)");
      auto* align = sub.add_option("--align-s", args->session.align_s,
                                   "Coarse alignment over the first SECONDS of the record (at "
                                   "rest); the trajectory starts in its middle");
      attitude->excludes(align);
      sub.add_option("--site", args->session.site,
                     "LAT,LON,H (deg, deg, m, WGS84) if the file names no site or to override it");
      sub.add_option("--smooth", args->session.smooth_spec,
                     "Sensor spec YAML: zero-velocity-aided smoothing with 1-sigma columns "
                     "(needs --align-s)");
      sub.add_option("--sensor-errors", args->session.sensor_errors,
                     "Sensor error model YAML (bias, scale factor, misalignment) to correct the "
                     "raw data with on read (datasets/FORMAT.md)");
      sub.add_option("--heading-deg", args->session.heading_deg,
                     "Initial heading from an external reference (deg clockwise from North of "
                     "the sensor's +Y axis), replacing gyrocompassing; with --align-s");
      sub.add_option("--heading-sigma-deg", args->session.heading_sigma_deg,
                     "1-sigma of --heading-deg (deg)")
          ->capture_default_str();
      sub.add_flag("--force", args->force, "Overwrite existing outputs");
      sub.callback([args] { run(*args); });
    }};

}  // namespace
