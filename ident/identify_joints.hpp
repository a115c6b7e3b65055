#pragma once
// The identification of every joint of a joint_errors.csv, as `imscal identify` and the
// verification run it. The joints are independent least-squares problems on their own data, so
// they run on worker threads (one joint per task, results in joint order and bit-identical to a
// sequential run: no joint's arithmetic depends on another's or on the thread).
#include <cstddef>
#include <functional>
#include <span>
#include <string>
#include <vector>

#include "ident/identification_config.hpp"
#include "ident/identified_structure.hpp"
#include "ident/joint_error_io.hpp"
#include "ident/joint_identification.hpp"

namespace imscal::ident {

struct JointOutcome {
  JointIdentification result;
  std::string failure;   // empty when identified; else why the joint got the neutral model
  double seconds = 0.0;  // wall time of this joint's identification
  // The drive structure its models imply (compliance, friction, transmission error) with 1σ,
  // beside the config's values.
  IdentifiedStructure structure;
};

// threads: worker threads, 0 = the machine's hardware concurrency (at most one per joint).
// A joint for which identify_joint throws std::runtime_error (no cell could be identified, e.g.
// the joint did not move) gets the neutral model (zero correction) and the reason in `failure`;
// the other joints' models are still good. InputError and std::logic_error propagate (the first
// in joint order). on_done(joint, joints_done) is called as each joint finishes (from the worker
// threads, one call at a time): progress for long runs.
// The table of an identification (robot, cycle, model form and preview from the config, the
// creating tool's version, the data source) without its joints.
ParameterTable parameter_table_header(const JointErrorLog& log, const IdentificationConfig& config,
                                      DataSource source);

// A joint identified without some of the table's inputs (the second transmission-error pair
// where the joint has no second order, the gear-mode pairs where it has no mode): each of its
// cells gets each missing input with one zero coefficient, as a neutral cell gets every input,
// and a joint without either second pair the second phase rate 0. joint_inputs must be a
// subsequence of table_inputs (extra_inputs_of keeps one order): std::logic_error otherwise.
void pad_absent_inputs(JointParameters& joint, std::span<const TableInput> joint_inputs,
                       std::span<const TableInput> table_inputs);

using JointDoneCallback = std::function<void(std::size_t joint, std::size_t joints_done)>;
std::vector<JointOutcome> identify_joints(const JointErrorLog& log,
                                          const IdentificationConfig& config, unsigned threads = 0,
                                          const JointDoneCallback& on_done = {});

}  // namespace imscal::ident
