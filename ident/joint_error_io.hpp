#pragma once
// joint_errors.csv: the joint angles of one or more robot runs, sampled every controller cycle,
// from which the ARX error models are identified (written by `imscal calibrate`, read by
// `imscal identify`; format in datasets/FORMAT.md, section "joint_errors.csv").
//
//   # imscal-joint-errors: 1
//   # robot: kr16
//   # cycle_s: 0.002
//   # source: ...                      (optional; further "# key: value" lines are kept)
//   t_s,payload_kg,q_desired_A1_rad,..,q_measured_A1_rad,..[,q_internal_A1_rad,..]
//
// q_desired: the robot's desired joint angle; q_measured: the joint angle reached, from the IMS
// chain (inverse kinematics of the measured flange pose); q_internal: the robot's motor encoders
// (joint side), optional as a whole block (a robot with one position sensor per joint has no
// second reading). The joint error of the paper is Δq = q_desired - q_measured.
// Time gaps longer than 1.5 cycles split the data into segments (separate runs; a warning, not
// an error); a time that does not increase is an error.
#include <cstddef>
#include <filesystem>
#include <fstream>
#include <ostream>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "core/atomic_file.hpp"

namespace imscal::ident {

struct JointErrorLog {
  std::string robot;
  double cycle_s = 0.002;  // nominal sample time [s]
  std::string source;      // where the data came from (free text)
  std::vector<std::pair<std::string, std::string>> metadata;  // further header keys, in order
  std::vector<std::string> joint_names;                       // "A1".."A6"
  std::vector<double> time_s;
  std::vector<double> payload_kg;
  // [joint][sample], SI (rad). q_internal_rad is empty (no joint) when the file has no
  // q_internal block.
  std::vector<std::vector<double>> q_desired_rad, q_measured_rad, q_internal_rad;
  // The joint torques of the robot's rigid-body model [joint][sample] [N m], along the path the
  // identification's model form reads (eval/model_torque.hpp); empty unless a caller attached
  // them for a multi-input identification. Not a column of joint_errors.csv.
  std::vector<std::vector<double>> model_torque_nm;
  // First sample of every segment (a run without gaps); segment_starts[0] == 0.
  std::vector<std::size_t> segment_starts{0};
  std::vector<std::size_t> sample_lines;  // 1-based file line of each sample (empty: not read)
  std::size_t first_data_line = 0;  // 1-based line of the first sample (0: not read from a file)

  std::size_t sample_count() const { return time_s.size(); }
  std::size_t joint_count() const { return joint_names.size(); }
  bool has_q_internal() const { return !q_internal_rad.empty(); }
  // [begin, end) sample ranges of the segments.
  std::vector<std::pair<std::size_t, std::size_t>> segments() const;
};

// Reads and validates a joint_errors.csv; InputError(file, line, field, problem) on bad input (a
// q_internal block that misses a joint's column among them).
JointErrorLog read_joint_errors_csv(const std::filesystem::path& file);

// Writes the log (17 significant digits, so a round trip is exact; the q_internal block only
// when the log has it), atomically. Throws
// std::invalid_argument for an inconsistent log (sizes, non-finite values, names).
void write_joint_errors_csv(const std::filesystem::path& file, const JointErrorLog& log,
                            Overwrite overwrite = Overwrite::kAllow);

// joint_errors.csv written one sample at a time (the bytes write_joint_errors_csv writes), for a
// caller that holds its rows in another layout and so needs no JointErrorLog copy of them.
class JointErrorsCsvWriter {
 public:
  // The header from `header`'s robot, cycle_s, source, metadata and joint_names (its columns
  // are not read); `with_internal`: the q_internal block. Throws std::invalid_argument for no
  // joints, a bad joint name or cycle_s <= 0, std::runtime_error when the file cannot be made.
  JointErrorsCsvWriter(const std::filesystem::path& file, const JointErrorLog& header,
                       bool with_internal, Overwrite overwrite = Overwrite::kAllow);
  // The header given at commit (a header value that depends on all rows): the rows wait in
  // `file`.rows beside the file (removed at commit or destruction), `joints` values per family.
  JointErrorsCsvWriter(const std::filesystem::path& file, std::size_t joints, bool with_internal,
                       Overwrite overwrite = Overwrite::kAllow);
  JointErrorsCsvWriter(const JointErrorsCsvWriter&) = delete;
  JointErrorsCsvWriter& operator=(const JointErrorsCsvWriter&) = delete;
  ~JointErrorsCsvWriter();
  // One sample, a value per joint in each span (q_internal not read without the block). Throws
  // std::invalid_argument for a non-finite value or a span of another size.
  void add(double t_s, double payload_kg, std::span<const double> q_desired_rad,
           std::span<const double> q_measured_rad, std::span<const double> q_internal_rad);
  void commit();
  // With the header given at commit: writes it (as the first constructor; its joint count must
  // be `joints`), then the rows, and commits.
  void commit(const JointErrorLog& header);

 private:
  std::ostream& rows();

  AtomicFile out_;
  std::size_t joints_ = 0;
  bool with_internal_ = false;
  std::size_t samples_ = 0;
  std::string line_;
  std::filesystem::path rows_file_;  // empty: the header is written and rows follow it in out_
  std::ofstream rows_out_;
};

// Re-derives segment_starts from the time stamps (gap > 1.5 cycle_s starts a segment).
void split_at_gaps(JointErrorLog& log);

// SHA-256 of a file's bytes as 64 lower-case hex digits (the data source checksum of
// parameters.json). Throws InputError when the file cannot be read.
std::string file_sha256_hex(const std::filesystem::path& file);

}  // namespace imscal::ident
