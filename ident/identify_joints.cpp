#include "ident/identify_joints.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <exception>
#include <mutex>
#include <thread>

#include "core/input_error.hpp"
#include "core/version.hpp"
#include "ident/identification_config_record.hpp"

namespace imscal::ident {
namespace {

IdentifiedStructure structure_beside_config(const JointIdentification& result,
                                            const IdentificationConfig& config, std::size_t joint) {
  // The joint's own inputs: a joint without a second transmission-error order was fitted
  // without that pair.
  JointIdentificationOptions options = config.joint_options(joint);
  if (options.transmission_error_mode_pairs == GearModePairs::kBeside &&
      !(result.parameters.transmission_error_mode_rad_s > 0.0))  // fitted without them
    options.transmission_error_mode_pairs = GearModePairs::kNone;
  const FitForm form{options.form == ArxModelForm::kInverse, options.preview_cycles};
  IdentifiedStructure s = identified_structure(result, extra_inputs_of(options), form);
  if (joint < config.gear_stiffness_nm_per_rad.size())
    s.nominal_compliance_rad_per_nm = 1.0 / config.gear_stiffness_nm_per_rad[joint];
  if (config.options.transmission_error_input)
    s.transmission_error_harmonic_per_motor_rev = config.transmission_error_harmonic(joint);
  return s;
}

// One joint's identification, padded to the table's inputs. Beside the plain pairs, a joint
// whose data leave the gear-mode pairs in the plain pairs' span (every candidate rank deficient:
// where the error's frequency stays well below the mode, H(jΩ) e^{jφ} is the plain pair through
// a short FIR, which the plain pairs' taps already are) is identified without them.
JointIdentification identify_one_joint(
    const JointErrorLog& log, const IdentificationConfig& config, std::size_t j,
    std::span<const std::pair<std::size_t, std::size_t>> segments) {
  const std::span<const double> torque =
      log.model_torque_nm.empty() ? std::span<const double>() : log.model_torque_nm[j];
  JointIdentificationOptions options = config.joint_options(j);
  const auto identify = [&] {
    return identify_joint(log.joint_names[j], log.q_desired_rad[j], log.q_measured_rad[j],
                          log.payload_kg, segments, log.cycle_s, config.joint_grid(j), options,
                          torque);
  };
  JointIdentification result;
  try {
    result = identify();
  } catch (const InputError&) {
    throw;
  } catch (const std::runtime_error&) {
    if (options.transmission_error_mode_pairs != GearModePairs::kBeside) throw;
    options.transmission_error_mode_pairs = GearModePairs::kNone;
    result = identify();
  }
  const std::vector<TableInput> joint_inputs = extra_inputs_of(options);
  const std::vector<TableInput> table_inputs = extra_inputs_of(config.options);
  if (joint_inputs != table_inputs)
    pad_absent_inputs(result.parameters, joint_inputs, table_inputs);
  return result;
}

// The config with its durations in counts of the log's cycle (ident/
// identification_config_record.hpp), checked against the log.
IdentificationConfig for_log(const IdentificationConfig& config, const JointErrorLog& log) {
  if (config.resolved_cycle_s == log.cycle_s) return config;
  return resolve_for_record(config, log.robot, log.cycle_s, "the joint errors");
}

}  // namespace

void pad_absent_inputs(JointParameters& joint, std::span<const TableInput> joint_inputs,
                       std::span<const TableInput> table_inputs) {
  if (table_inputs.size() > std::size_t(kMaxExtraInputs))
    throw std::logic_error("pad_absent_inputs: too many further inputs");
  for (CellParameters& cell : joint.cells) {
    ArxStructure padded = cell.structure;
    padded.extra_inputs = int(table_inputs.size());
    padded.nx.fill(0);
    std::vector<double> c;
    std::size_t from = 0;
    for (std::size_t e = 0; e < table_inputs.size(); ++e) {
      const bool present = from < joint_inputs.size() && joint_inputs[from] == table_inputs[e];
      const int nx = present ? cell.structure.nx[from] : 1;
      const auto first = cell.c.begin() + (present ? cell.structure.extra_offset(int(from)) : 0);
      if (present)
        c.insert(c.end(), first, first + nx);
      else
        c.push_back(0.0);
      padded.nx[e] = nx;
      from += present ? 1 : 0;
    }
    if (from != joint_inputs.size())
      throw std::logic_error("pad_absent_inputs: the joint's inputs are not the table's");
    cell.structure = padded;
    cell.c = std::move(c);
  }
  if (!has_input(joint_inputs, TableInput::kTransmissionError2Sin) &&
      !has_input(joint_inputs, TableInput::kTransmissionError2ModeSin))
    joint.transmission_error_2_rad_per_rad = 0.0;
}

ParameterTable parameter_table_header(const JointErrorLog& log,
                                      const IdentificationConfig& given_config, DataSource source) {
  const IdentificationConfig config = for_log(given_config, log);
  ParameterTable table;
  table.robot = log.robot;
  table.sample_time_s = log.cycle_s;
  table.created_by = std::string("imscal ") + kVersion;
  table.model_form =
      config.options.form == ArxModelForm::kInverse ? TableForm::kInverse : TableForm::kForward;
  table.preview_cycles = config.options.preview_cycles;
  table.extra_inputs = extra_inputs_of(config.options);
  table.direction_speed_scale_rad_s = config.options.direction_speed_scale_rad_s;
  table.source = std::move(source);
  return table;
}

std::vector<JointOutcome> identify_joints(const JointErrorLog& log,
                                          const IdentificationConfig& given_config,
                                          unsigned threads, const JointDoneCallback& on_done) {
  const IdentificationConfig config = for_log(given_config, log);
  const std::size_t joints = log.joint_count();
  std::vector<JointOutcome> outcomes(joints);
  std::vector<std::exception_ptr> errors(joints);
  if (config.options.model_torque_input && log.model_torque_nm.size() != joints)
    throw std::invalid_argument(
        "identify_joints: the config's models take the model torque, but no torques are attached "
        "to the joint errors (the robot's rigid-body model is needed: eval/model_torque.hpp)");
  const auto segments = log.segments();
  std::atomic<std::size_t> next{0};
  std::mutex done_mutex;
  std::size_t done = 0;
  auto work = [&] {
    for (std::size_t j = next++; j < joints; j = next++) {
      const auto start = std::chrono::steady_clock::now();
      try {
        outcomes[j].result = identify_one_joint(log, config, j, segments);
      } catch (const InputError&) {
        errors[j] = std::current_exception();
      } catch (const std::runtime_error& e) {
        outcomes[j].failure = e.what();
        outcomes[j].result =
            neutral_joint_identification(log.joint_names[j], config.max_speed_rad_s[j], e.what(),
                                         extra_input_count(config.options));
        // A table with the torque-sign input needs a scale for every joint; the neutral cell's
        // coefficient is zero, so any positive one serves.
        if (config.options.torque_sign_input)
          outcomes[j].result.parameters.torque_sign_scale_nm = 1.0;
        if (config.options.transmission_error_input) {
          const JointIdentificationOptions o = config.joint_options(j);
          outcomes[j].result.parameters.transmission_error_rad_per_rad =
              o.transmission_error_rad_per_rad;
          if (o.second_transmission_error_input)
            outcomes[j].result.parameters.transmission_error_2_rad_per_rad =
                o.transmission_error_2_rad_per_rad;
        }
      } catch (...) {
        errors[j] = std::current_exception();
      }
      if (!errors[j])
        outcomes[j].structure = structure_beside_config(outcomes[j].result, config, j);
      outcomes[j].seconds =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      const std::lock_guard lock(done_mutex);
      ++done;
      if (on_done) on_done(j, done);
    }
  };
  if (threads == 0) threads = std::max(1u, std::thread::hardware_concurrency());
  const std::size_t helpers = std::min<std::size_t>(threads, joints) - (joints > 0 ? 1 : 0);
  std::vector<std::jthread> pool;
  for (std::size_t i = 0; i < helpers; ++i) pool.emplace_back(work);
  work();        // this thread takes tasks too
  pool.clear();  // joins
  for (const auto& error : errors)
    if (error) std::rethrow_exception(error);
  return outcomes;
}

}  // namespace imscal::ident
