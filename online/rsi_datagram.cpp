#include "online/rsi_datagram.hpp"

#include <charconv>
#include <cmath>
#include <cstring>

namespace imscal::online {
namespace {

bool is_space(char c) {
  return c == ' ' || c == '\t' || c == '\n' || c == '\r';
}

bool is_name_char(char c) {
  return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' ||
         c == '-' || c == '.' || c == ':';
}

bool equals_ignoring_case(std::string_view a, std::string_view b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i) {
    const auto lower = [](char c) { return c >= 'A' && c <= 'Z' ? char(c - 'A' + 'a') : c; };
    if (lower(a[i]) != lower(b[i])) return false;
  }
  return true;
}

std::string_view trimmed(std::string_view s) {
  while (!s.empty() && is_space(s.front())) s.remove_prefix(1);
  while (!s.empty() && is_space(s.back())) s.remove_suffix(1);
  return s;
}

// A number of an axis attribute: decimal or exponent form, an optional sign, "nan" / "inf".
bool parse_number(std::string_view text, double* value) {
  text = trimmed(text);
  if (!text.empty() && text.front() == '+') text.remove_prefix(1);
  if (text.empty()) return false;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), *value);
  return ec == std::errc() && end == text.data() + text.size();
}

enum class Element : std::uint8_t { kOther, kIpoc, kSetpoint, kActual };

// A scanner over the datagram; every read checks the end (the text need not be terminated).
class Scanner {
 public:
  Scanner(std::string_view text, RsiRobotDatagram* out) : text_(text), out_(out) {}
  RsiParseError parse();

 private:
  bool at(std::string_view s) const { return text_.substr(pos_, s.size()) == s; }
  bool done() const { return pos_ >= text_.size(); }
  void skip_space() {
    while (!done() && is_space(text_[pos_])) ++pos_;
  }
  // Moves past the next `terminator`; false when there is none.
  bool skip_past(std::string_view terminator) {
    const std::size_t found = text_.find(terminator, pos_);
    if (found == std::string_view::npos) return false;
    pos_ = found + terminator.size();
    return true;
  }
  std::string_view name() {
    const std::size_t begin = pos_;
    while (!done() && is_name_char(text_[pos_])) ++pos_;
    return text_.substr(begin, pos_ - begin);
  }
  bool skip_misc();  // whitespace, comments, processing instructions
  RsiParseError open_tag(std::string_view tag, Element element, bool root, bool* self_closing);
  RsiParseError attribute(std::string_view attr, std::string_view value, Element element, bool root,
                          unsigned* axes);
  RsiParseError content();
  RsiParseError finish() const;

  std::string_view text_;
  std::size_t pos_ = 0;
  RsiRobotDatagram* out_;
  bool seen_ipoc_ = false, seen_setpoint_ = false;
};

bool Scanner::skip_misc() {
  for (;;) {
    skip_space();
    if (at("<?")) {
      if (!skip_past("?>")) return false;
    } else if (at("<!--")) {
      if (!skip_past("-->")) return false;
    } else {
      return true;
    }
  }
}

RsiParseError Scanner::attribute(std::string_view attr, std::string_view value, Element element,
                                 bool root, unsigned* axes) {
  if (root && equals_ignoring_case(attr, "type")) {
    if (value.size() > std::size_t(kRsiMaxTypeBytes)) return RsiParseError::kTypeTooLong;
    std::memcpy(out_->type.data(), value.data(), value.size());
    out_->type_bytes = int(value.size());
    return RsiParseError::kNone;
  }
  if (element != Element::kSetpoint && element != Element::kActual) return RsiParseError::kNone;
  if (attr.size() != 2 || attr[0] != 'A' || attr[1] < '1' || attr[1] > '6')
    return RsiParseError::kNone;  // external axes E1.. and the like
  const int axis = attr[1] - '1';
  if (*axes & (1u << axis)) return RsiParseError::kMalformedXml;  // repeated attribute
  *axes |= 1u << axis;
  double* target = element == Element::kSetpoint ? &out_->setpoint_deg[std::size_t(axis)]
                                                 : &out_->actual_deg[std::size_t(axis)];
  return parse_number(value, target) ? RsiParseError::kNone : RsiParseError::kBadNumber;
}

// After the name of an opening tag: its attributes up to '>' or '/>'.
RsiParseError Scanner::open_tag(std::string_view tag, Element element, bool root,
                                bool* self_closing) {
  (void)tag;
  unsigned axes = 0;
  for (;;) {
    skip_space();
    if (done()) return RsiParseError::kMalformedXml;
    if (text_[pos_] == '>' || at("/>")) {
      *self_closing = text_[pos_] == '/';
      pos_ += *self_closing ? 2 : 1;
      break;
    }
    const std::string_view attr = name();
    if (attr.empty()) return RsiParseError::kMalformedXml;
    skip_space();
    if (done() || text_[pos_] != '=') return RsiParseError::kMalformedXml;
    ++pos_;
    skip_space();
    if (done() || (text_[pos_] != '"' && text_[pos_] != '\'')) return RsiParseError::kMalformedXml;
    const char quote = text_[pos_++];
    const std::size_t end = text_.find(quote, pos_);
    if (end == std::string_view::npos) return RsiParseError::kMalformedXml;
    const std::string_view value = text_.substr(pos_, end - pos_);
    if (value.find('<') != std::string_view::npos) return RsiParseError::kMalformedXml;
    pos_ = end + 1;
    if (const RsiParseError e = attribute(attr, value, element, root, &axes);
        e != RsiParseError::kNone)
      return e;
  }
  if ((element == Element::kSetpoint || element == Element::kActual) && axes != 0x3fu)
    return RsiParseError::kMissingAxis;
  return RsiParseError::kNone;
}

Element classify(std::string_view tag, int depth) {
  if (depth != 1) return Element::kOther;  // only the children of <Rob>
  if (tag == "IPOC") return Element::kIpoc;
  if (tag == "ASPos") return Element::kSetpoint;
  if (tag == "AIPos") return Element::kActual;
  return Element::kOther;
}

// The elements inside <Rob>, up to its closing tag.
RsiParseError Scanner::content() {
  std::array<std::string_view, kRsiMaxDepth> open{};
  open[0] = "Rob";
  int depth = 1;
  std::size_t ipoc_text_begin = 0;
  bool in_ipoc = false;
  while (depth > 0) {
    const std::size_t lt = text_.find('<', pos_);
    if (lt == std::string_view::npos) return RsiParseError::kMalformedXml;
    pos_ = lt;
    if (at("<!--")) {
      if (!skip_past("-->")) return RsiParseError::kMalformedXml;
      continue;
    }
    if (at("</")) {
      pos_ += 2;
      const std::string_view tag = name();
      skip_space();
      if (tag != open[std::size_t(depth - 1)] || done() || text_[pos_] != '>')
        return RsiParseError::kMalformedXml;
      if (in_ipoc) {
        std::string_view digits = trimmed(text_.substr(ipoc_text_begin, lt - ipoc_text_begin));
        const auto [end, ec] =
            std::from_chars(digits.data(), digits.data() + digits.size(), out_->ipoc);
        if (digits.empty() || ec != std::errc() || end != digits.data() + digits.size())
          return RsiParseError::kBadIpoc;
        in_ipoc = false;
      }
      ++pos_;
      --depth;
      continue;
    }
    ++pos_;
    const std::string_view tag = name();
    if (tag.empty() || in_ipoc)
      return in_ipoc ? RsiParseError::kBadIpoc : RsiParseError::kMalformedXml;
    const Element element = classify(tag, depth);
    bool& seen = element == Element::kIpoc       ? seen_ipoc_
                 : element == Element::kSetpoint ? seen_setpoint_
                                                 : out_->has_actual;
    if (element != Element::kOther) {
      if (seen) return RsiParseError::kRepeatedElement;
      seen = true;
    }
    bool self_closing = false;
    if (const RsiParseError e = open_tag(tag, element, false, &self_closing);
        e != RsiParseError::kNone)
      return e;
    if (element == Element::kIpoc && self_closing) return RsiParseError::kBadIpoc;
    if (self_closing) continue;
    if (depth == kRsiMaxDepth) return RsiParseError::kTooDeep;
    open[std::size_t(depth++)] = tag;
    in_ipoc = element == Element::kIpoc;
    ipoc_text_begin = pos_;
  }
  return RsiParseError::kNone;
}

RsiParseError Scanner::finish() const {
  if (!seen_ipoc_) return RsiParseError::kMissingIpoc;
  if (!seen_setpoint_) return RsiParseError::kMissingSetpoint;
  return RsiParseError::kNone;
}

RsiParseError Scanner::parse() {
  if (text_.size() > std::size_t(kRsiMaxDatagramBytes)) return RsiParseError::kTooLong;
  if (!skip_misc() || done() || text_[pos_] != '<') return RsiParseError::kMalformedXml;
  ++pos_;
  const std::string_view root = name();
  if (root != "Rob") return root.empty() ? RsiParseError::kMalformedXml : RsiParseError::kNotRob;
  bool self_closing = false;
  if (const RsiParseError e = open_tag(root, Element::kOther, true, &self_closing);
      e != RsiParseError::kNone)
    return e;
  if (!self_closing) {
    if (const RsiParseError e = content(); e != RsiParseError::kNone) return e;
  }
  if (!skip_misc() || !done()) return RsiParseError::kMalformedXml;  // only misc after the root
  return finish();
}

// Appends `s` at *pos if it fits.
bool append(char* buffer, int capacity, int* pos, std::string_view s) {
  if (int(s.size()) > capacity - *pos) return false;
  std::memcpy(buffer + *pos, s.data(), s.size());
  *pos += int(s.size());
  return true;
}

}  // namespace

const char* to_string(RsiParseError error) {
  switch (error) {
    case RsiParseError::kNone:
      return "none";
    case RsiParseError::kTooLong:
      return "datagram too long";
    case RsiParseError::kMalformedXml:
      return "malformed XML";
    case RsiParseError::kTooDeep:
      return "elements nested too deep";
    case RsiParseError::kNotRob:
      return "root element is not <Rob>";
    case RsiParseError::kMissingIpoc:
      return "no <IPOC>";
    case RsiParseError::kBadIpoc:
      return "IPOC is not an unsigned integer";
    case RsiParseError::kMissingSetpoint:
      return "no <ASPos>";
    case RsiParseError::kMissingAxis:
      return "axis values A1..A6 incomplete";
    case RsiParseError::kBadNumber:
      return "axis value is not a number";
    case RsiParseError::kRepeatedElement:
      return "IPOC, ASPos or AIPos repeated";
    case RsiParseError::kTypeTooLong:
      return "Type attribute too long";
  }
  return "?";
}

RsiParseError parse_rsi_robot_datagram(std::string_view text, RsiRobotDatagram* out) noexcept {
  *out = RsiRobotDatagram{};
  return Scanner(text, out).parse();
}

double rsi_written_value(double correction_deg) noexcept {
  constexpr double scale = 1e6;  // 10^kRsiCorrectionDecimals
  static_assert(kRsiCorrectionDecimals == 6);
  return std::round(correction_deg * scale) / scale;
}

int write_rsi_answer(std::string_view sensor_type,
                     const std::array<double, kRsiAxes>& correction_deg, std::uint64_t ipoc,
                     char* buffer, int capacity) noexcept {
  for (char c : sensor_type)
    if (c == '"' || c == '<' || c == '&') return -1;
  int pos = 0;
  bool fits = append(buffer, capacity, &pos, "<Sen Type=\"") &&
              append(buffer, capacity, &pos, sensor_type) &&
              append(buffer, capacity, &pos, "\"><AKorr");
  constexpr std::array<std::string_view, kRsiAxes> names{" A1=\"", " A2=\"", " A3=\"",
                                                         " A4=\"", " A5=\"", " A6=\""};
  std::array<char, 64> number{};
  for (int a = 0; a < kRsiAxes && fits; ++a) {
    const double value = rsi_written_value(correction_deg[std::size_t(a)]);
    if (!std::isfinite(value)) return -1;
    // Writing -0 as 0: the controller's parser and a reader of the log need no "-0.000000".
    const auto [end, ec] =
        std::to_chars(number.data(), number.data() + number.size(), value == 0.0 ? 0.0 : value,
                      std::chars_format::fixed, kRsiCorrectionDecimals);
    if (ec != std::errc()) return -1;
    fits = append(buffer, capacity, &pos, names[std::size_t(a)]) &&
           append(buffer, capacity, &pos, std::string_view(number.data(), end - number.data())) &&
           append(buffer, capacity, &pos, "\"");
  }
  const auto [ipoc_end, ipoc_ec] =
      std::to_chars(number.data(), number.data() + number.size(), ipoc);
  fits =
      fits && ipoc_ec == std::errc() && append(buffer, capacity, &pos, "/><IPOC>") &&
      append(buffer, capacity, &pos, std::string_view(number.data(), ipoc_end - number.data())) &&
      append(buffer, capacity, &pos, "</IPOC></Sen>");
  return fits ? pos : -1;
}

}  // namespace imscal::online
