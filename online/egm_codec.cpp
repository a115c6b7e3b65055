#include "online/egm_codec.hpp"

#include <cmath>

#include "egm.pb.h"

namespace imscal::online {

const char* to_string(EgmParseError error) {
  switch (error) {
    case EgmParseError::kNone:
      return "no error";
    case EgmParseError::kTooLong:
      return "datagram too long";
    case EgmParseError::kNotProtobuf:
      return "not an EgmRobot message";
    case EgmParseError::kMissingHeader:
      return "no header with a seqno";
    case EgmParseError::kNotData:
      return "header mtype is not MSGTYPE_DATA";
    case EgmParseError::kMissingFeedback:
      return "no feedBack joints";
    case EgmParseError::kTooManyJoints:
      return "more joints than accepted";
  }
  return "?";
}

struct EgmCodec::Messages {
  egm::EgmRobot robot;
  egm::EgmSensor sensor;
};

EgmCodec::EgmCodec() : messages_(std::make_unique<Messages>()) {
  // The answer's constant parts once; write_sensor only overwrites values.
  egm::EgmHeader* header = messages_->sensor.mutable_header();
  header->set_mtype(egm::EgmHeader::MSGTYPE_CORRECTION);
  egm::EgmJoints* joints = messages_->sensor.mutable_planned()->mutable_joints();
  for (int a = 0; a < kEgmAxes; ++a) joints->add_joints(0.0);
}

EgmCodec::~EgmCodec() = default;

namespace {

// Copies a repeated joint field; false when it has more than kEgmMaxJoints values.
bool copy_joints(const egm::EgmJoints& from, int* count, std::array<double, kEgmMaxJoints>* to) {
  if (from.joints_size() > kEgmMaxJoints) return false;
  *count = from.joints_size();
  for (int i = 0; i < *count; ++i) (*to)[std::size_t(i)] = from.joints(i);
  return true;
}

}  // namespace

EgmParseError EgmCodec::parse_robot(std::string_view bytes, EgmRobotDatagram* out) noexcept {
  if (bytes.size() > std::size_t(kEgmMaxDatagramBytes)) return EgmParseError::kTooLong;
  egm::EgmRobot& robot = messages_->robot;
  // Partial parse and our own check of the required fields: ParseFromArray logs the missing ones.
  if (!robot.ParsePartialFromArray(bytes.data(), int(bytes.size())) || !robot.IsInitialized())
    return EgmParseError::kNotProtobuf;
  if (!robot.has_header() || !robot.header().has_seqno()) return EgmParseError::kMissingHeader;
  if (robot.header().mtype() != egm::EgmHeader::MSGTYPE_DATA) return EgmParseError::kNotData;
  if (!robot.has_feedback() || !robot.feedback().has_joints())
    return EgmParseError::kMissingFeedback;
  out->seqno = robot.header().seqno();
  out->tm_ms = robot.header().tm();
  if (!copy_joints(robot.feedback().joints(), &out->feedback_joints, &out->feedback_deg))
    return EgmParseError::kTooManyJoints;
  out->planned_joints = 0;
  if (robot.has_planned() && robot.planned().has_joints() &&
      !copy_joints(robot.planned().joints(), &out->planned_joints, &out->planned_deg))
    return EgmParseError::kTooManyJoints;
  out->motors = EgmMotors::kUndefined;
  if (robot.has_motorstate()) {
    const auto state = robot.motorstate().state();
    out->motors = state == egm::EgmMotorState::MOTORS_ON    ? EgmMotors::kOn
                  : state == egm::EgmMotorState::MOTORS_OFF ? EgmMotors::kOff
                                                            : EgmMotors::kUndefined;
  }
  return EgmParseError::kNone;
}

int EgmCodec::write_sensor(std::uint32_t seqno, std::uint32_t tm_ms,
                           const std::array<double, kEgmAxes>& planned_deg, char* buffer,
                           int capacity) noexcept {
  egm::EgmSensor& sensor = messages_->sensor;
  sensor.mutable_header()->set_seqno(seqno);
  sensor.mutable_header()->set_tm(tm_ms);
  egm::EgmJoints* joints = sensor.mutable_planned()->mutable_joints();
  for (int a = 0; a < kEgmAxes; ++a) {
    if (!std::isfinite(planned_deg[std::size_t(a)])) return -1;
    joints->set_joints(a, planned_deg[std::size_t(a)]);
  }
  const std::size_t bytes = sensor.ByteSizeLong();
  if (bytes > std::size_t(capacity) || !sensor.SerializeToArray(buffer, int(bytes))) return -1;
  return int(bytes);
}

int EgmCodec::write_robot(const EgmRobotDatagram& d, char* buffer, int capacity) noexcept {
  egm::EgmRobot robot;  // the controller's side: not in a served cycle
  egm::EgmHeader* header = robot.mutable_header();
  header->set_seqno(d.seqno);
  header->set_tm(d.tm_ms);
  header->set_mtype(egm::EgmHeader::MSGTYPE_DATA);
  egm::EgmJoints* feedback = robot.mutable_feedback()->mutable_joints();
  for (int i = 0; i < d.feedback_joints && i < kEgmMaxJoints; ++i)
    feedback->add_joints(d.feedback_deg[std::size_t(i)]);
  if (d.planned_joints > 0) {
    egm::EgmJoints* planned = robot.mutable_planned()->mutable_joints();
    for (int i = 0; i < d.planned_joints && i < kEgmMaxJoints; ++i)
      planned->add_joints(d.planned_deg[std::size_t(i)]);
  }
  if (d.motors != EgmMotors::kUndefined)
    robot.mutable_motorstate()->set_state(d.motors == EgmMotors::kOn
                                              ? egm::EgmMotorState::MOTORS_ON
                                              : egm::EgmMotorState::MOTORS_OFF);
  const std::size_t bytes = robot.ByteSizeLong();
  if (bytes > std::size_t(capacity) || !robot.SerializeToArray(buffer, int(bytes))) return -1;
  return int(bytes);
}

bool EgmCodec::parse_sensor(std::string_view bytes, std::uint32_t* seqno,
                            std::array<double, kEgmAxes>* planned_deg) noexcept {
  egm::EgmSensor sensor;
  if (!sensor.ParsePartialFromArray(bytes.data(), int(bytes.size())) || !sensor.IsInitialized())
    return false;
  if (!sensor.has_header() || !sensor.header().has_seqno() || !sensor.has_planned() ||
      sensor.planned().joints().joints_size() != kEgmAxes)
    return false;
  *seqno = sensor.header().seqno();
  for (int a = 0; a < kEgmAxes; ++a)
    (*planned_deg)[std::size_t(a)] = sensor.planned().joints().joints(a);
  return true;
}

}  // namespace imscal::online
