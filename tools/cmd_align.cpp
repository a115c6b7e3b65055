// `imscal align`: coarse alignment at rest (levelling + gyrocompassing) of a raw IMS record,
// with the 1-sigma of each angle; optionally per disjoint window to show their agreement
// (ims/alignment_session.hpp). Angles and frames: ims/coarse_alignment.hpp (heading clockwise
// from North of the sensor's +Y axis; PSINS yaw = counter-clockwise).
#include <iostream>
#include <memory>
#include <string>

#include "core/atomic_file.hpp"
#include "core/json_output.hpp"
#include "ims/alignment_session.hpp"
#include "tools/command_registry.hpp"

namespace {

struct AlignArgs {
  imscal::ims::AlignmentSessionOptions session;
  std::string out;
};

void run(const AlignArgs& args) {
  const imscal::ims::AlignmentSession result = imscal::ims::align_session(args.session);
  imscal::write_file_atomically(args.out, imscal::json_text(result.document, 2, args.out));
  std::cout << result.summary << "written: " << args.out << "\n";
}

imscal::tools::CommandRegistration registration{
    "align", "Coarse alignment at rest: roll, pitch, heading (gyrocompassing) with 1-sigma",
    [](CLI::App& sub) {
      auto args = std::make_shared<AlignArgs>();
      sub.add_option("--input", args->session.input, "Raw IMS file (.imu PSINS, .csv, .imsb)")
          ->required();
      sub.add_option("--out", args->out, "Result JSON (written atomically)")->required();
      sub.add_option("--start-s", args->session.start_s,
                     "Start of the rest interval, seconds after the record start (default 0)");
      sub.add_option("--duration-s", args->session.duration_s,
                     "Length of the rest interval [s] (default: to the end of the record)");
      sub.add_option("--window-s", args->session.window_s,
                     "Also align disjoint windows of this length [s] inside the interval");
      sub.add_option("--site", args->session.site,
                     "LAT,LON,H (deg, deg, m, WGS84) if the file names no site or to override it");
      sub.add_option("--block-count", args->session.block_count,
                     "Blocks per interval for the line fit and the noise model (>= 8)")
          ->check(CLI::Range(8, 100000));
      sub.callback([args] { run(*args); });
    }};

}  // namespace
