#include "glint/cluster/launch.h"

#include <tbb/info.h>

#include <algorithm>
#include <charconv>
#include <cstdlib>
#include <string_view>
#include <thread>

namespace glint::cluster {
namespace {

bool isSet(const char* name) {
  const char* value = std::getenv(name);
  return value != nullptr && *value != '\0';
}

std::optional<int> positiveNumber(const char* name) {
  const char* value = std::getenv(name);
  if (value == nullptr) return std::nullopt;
  const std::string_view text(value);
  int number = 0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), number);
  if (error != std::errc{} || end != text.data() + text.size() || number < 1) return std::nullopt;
  return number;
}

}  // namespace

bool launchedByMpi() {
  return isSet("OMPI_COMM_WORLD_SIZE") || isSet("PMIX_RANK") ||
         (isSet("PMI_RANK") && isSet("PMI_SIZE"));
}

std::optional<int> ranksOnThisHost() {
  for (const char* name :
       {"OMPI_COMM_WORLD_LOCAL_SIZE", "SLURM_NTASKS_PER_NODE", "MPI_LOCALNRANKS"})
    if (const std::optional<int> count = positiveNumber(name)) return count;
  return std::nullopt;
}

int defaultThreadsPerRank() {
  const int allowed = std::max(1, tbb::info::default_concurrency());
  const int cores = static_cast<int>(std::thread::hardware_concurrency());
  // Bound to some cores by the launcher (mpirun binds to cores for up to 2 ranks, srun per its
  // --cpu-bind): those are this rank's alone.
  if (cores <= 0 || allowed < cores) return allowed;
  return std::max(1, allowed / ranksOnThisHost().value_or(1));
}

}  // namespace glint::cluster
