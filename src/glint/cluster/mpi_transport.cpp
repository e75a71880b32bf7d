#include "glint/cluster/mpi_transport.h"

#include <stdexcept>
#include <string_view>

namespace glint::cluster {

MpiTransport& mpiTransport() {
#ifdef GLINT_MPI_MODULE_BUILD_PATH
  constexpr std::string_view kBuildPath = GLINT_MPI_MODULE_BUILD_PATH;
#else
  constexpr std::string_view kBuildPath;
#endif
#ifdef GLINT_MPI_MODULE_INSTALL_PATH
  constexpr std::string_view kInstallPath = GLINT_MPI_MODULE_INSTALL_PATH;
#else
  constexpr std::string_view kInstallPath;
#endif
  static std::string error;
  static void* const entry =
      loadHelperModule(kMpiModuleFile, "GLINT_MPI_MODULE", kBuildPath, kInstallPath,
                       kMpiModuleIdentity, kMpiTransportFunction, error);
  if (entry == nullptr) throw std::runtime_error("cannot start MPI: " + error);
  static MpiTransport* const transport = reinterpret_cast<MpiTransportFunction>(entry)();
  return *transport;
}

}  // namespace glint::cluster
