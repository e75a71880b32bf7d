#include "glint/cluster/mpi_transport.h"

#include <stdexcept>
#include <string_view>

namespace glint::cluster {

MpiTransport& mpiTransport() {
  static std::string error;
  static void* const entry = loadHelperModule(
      kMpiModuleFile, "GLINT_MPI_MODULE", GLINT_HELPER_BUILD_PATH_OR_EMPTY,
      GLINT_HELPER_INSTALL_PATH_OR_EMPTY, kMpiModuleIdentity, kMpiTransportFunction, error);
  if (entry == nullptr) throw std::runtime_error("cannot start MPI: " + error);
  static MpiTransport* const transport = reinterpret_cast<MpiTransportFunction>(entry)();
  return *transport;
}

}  // namespace glint::cluster
