#include "core/memory_budget.hpp"

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>

#include "core/errors.hpp"

namespace flexmbd {

std::optional<double> availableMemoryBytes() {
  std::optional<double> bytes;
  std::ifstream meminfo("/proc/meminfo");
  for (std::string line; std::getline(meminfo, line);) {
    std::istringstream in(line);
    std::string key;
    double kb = 0.0;
    if (in >> key >> kb && key == "MemAvailable:") {
      bytes = kb * 1024.0;
      break;
    }
  }
  if (const char* limit = std::getenv("FLEXMBD_MEMORY_LIMIT_MB")) {
    char* end = nullptr;
    const double mb = std::strtod(limit, &end);
    if (end != limit && mb > 0.0 && (!bytes || mb * 1048576.0 < *bytes)) bytes = mb * 1048576.0;
  }
  return bytes;
}

std::string memoryText(double bytes) {
  char buf[32];
  if (bytes >= 1e9) {
    std::snprintf(buf, sizeof buf, "%.1f GB", bytes / 1e9);
  } else {
    std::snprintf(buf, sizeof buf, "%.0f MB", bytes / 1e6);
  }
  return buf;
}

void requireMemory(double bytes, const std::string& who, const std::string& what) {
  const std::optional<double> available = availableMemoryBytes();
  if (available && bytes > *available) {
    throw InputError(who + ": " + what + " needs about " + memoryText(bytes) + " of memory, more than the " +
                     memoryText(*available) +
                     " this machine has available (refused before allocating it; fewer elements, or a modal "
                     "reduction with \"modes\", need less: docs/stability.md, \"Sizes\")");
  }
}

}  // namespace flexmbd
