#include "variational_formation_core/common/yaml_text.hpp"

#include <cstdio>

namespace vf {

namespace {

/// Length of the valid UTF-8 sequence that starts at text[k] (k < text.size()), or 0 if none.
std::size_t utf8Length(const std::string& text, std::size_t k) {
  const auto byte = [&text](std::size_t i) { return static_cast<unsigned char>(text[i]); };
  const unsigned char lead = byte(k);
  std::size_t length = 0;
  unsigned long low = 0;  // the smallest code point this length may carry (no overlong forms)
  if (lead >= 0xC2 && lead <= 0xDF) {
    length = 2, low = 0x80;
  } else if (lead >= 0xE0 && lead <= 0xEF) {
    length = 3, low = 0x800;
  } else if (lead >= 0xF0 && lead <= 0xF4) {
    length = 4, low = 0x10000;
  } else {
    return 0;
  }
  if (k + length > text.size()) return 0;
  unsigned long code = lead & (0x7F >> length);
  for (std::size_t i = 1; i < length; ++i) {
    if ((byte(k + i) & 0xC0) != 0x80) return 0;
    code = (code << 6) | (byte(k + i) & 0x3F);
  }
  if (code < low || code > 0x10FFFF || (code >= 0xD800 && code <= 0xDFFF)) return 0;
  return length;
}

}  // namespace

std::string yamlQuoted(const std::string& text) {
  std::string out = "\"";
  for (std::size_t k = 0; k < text.size();) {
    const auto c = static_cast<unsigned char>(text[k]);
    if (c >= 0x80) {
      const std::size_t length = utf8Length(text, k);
      if (length == 0) {
        out += "\\uFFFD";
        ++k;
      } else {
        out.append(text, k, length);
        k += length;
      }
      continue;
    }
    ++k;
    switch (c) {
      case '"': out += "\\\""; break;
      case '\\': out += "\\\\"; break;
      case '\n': out += "\\n"; break;
      case '\t': out += "\\t"; break;
      case '\r': out += "\\r"; break;
      default:
        if (c < 0x20 || c == 0x7F) {
          char escaped[8];
          std::snprintf(escaped, sizeof escaped, "\\x%02X", static_cast<unsigned>(c));
          out += escaped;
        } else {
          out += static_cast<char>(c);
        }
    }
  }
  return out + "\"";
}

}  // namespace vf
