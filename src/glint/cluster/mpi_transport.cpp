#include "glint/cluster/mpi_transport.h"

#include <stdexcept>
#include <string_view>

namespace glint::cluster {

MpiTransport& mpiTransport() {
  static std::string error;
  static void* const entry =
      loadHelperModule(kMpiModuleFile, "GLINT_MPI_MODULE", GLINT_HELPER_PATHS, kMpiModuleIdentity,
                       kMpiTransportFunction, error);
  if (entry == nullptr) throw std::runtime_error("cannot start MPI: " + error);
  static MpiTransport* const transport = reinterpret_cast<MpiTransportFunction>(entry)();
  return *transport;
}

}  // namespace glint::cluster
