#pragma once

#include <string>

namespace vf {

/**
 * `text` as a YAML double-quoted scalar, for the lines of a file that YAML readers load (the
 * monitor's result file): `"` and `\` escaped, control characters as \n, \t, \r or \xNN, valid
 * UTF-8 kept as it is, and a byte that is not valid UTF-8 as \uFFFD (the replacement character).
 * Any text reads back as itself (apart from such bytes), whatever quotes, colons, hashes,
 * backslashes or line breaks it holds.
 */
std::string yamlQuoted(const std::string& text);

}  // namespace vf
