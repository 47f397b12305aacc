#include "variational_formation/tools/progress.hpp"

#include <ostream>
#include <string>

namespace vf {

void drawProgressBar(std::ostream& err, long done, long total) {
  const int width = 40;
  const int filled = total > 0 ? static_cast<int>(width * done / total) : width;
  err << "\r[" << std::string(static_cast<std::size_t>(filled), '#')
      << std::string(static_cast<std::size_t>(width - filled), ' ') << "] " << done << '/'
      << total << std::flush;
}

}  // namespace vf
