/// @file
/// The memory a model may take: what this machine has available, and the refusal, before
/// the big allocations, of a model whose estimate exceeds it (docs/stability.md, "Sizes").
#pragma once

#include <optional>
#include <string>

namespace flexmbd {

/// The bytes available to a new model: MemAvailable of /proc/meminfo, capped by the
/// environment variable FLEXMBD_MEMORY_LIMIT_MB where it is set (a test's or a shared
/// machine's budget); nullopt where neither is known.
std::optional<double> availableMemoryBytes();

/// "1.2 GB", "350 MB": a byte count for a message.
std::string memoryText(double bytes);

/// @throws InputError "<who>: <what> needs about <bytes> of memory, more than the <available>
/// this machine has available ..." when bytes exceeds availableMemoryBytes().
void requireMemory(double bytes, const std::string& who, const std::string& what);

}  // namespace flexmbd
