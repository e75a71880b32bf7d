// The mesh reader program's side of the import in a child process (import_child.h): reads one
// file with importMesh (assimp, or glint's own OBJ parse) and writes the answer. In
// glint_mesh_import with the other sources that link assimp, so that the renderer and libglint,
// which only start the reader, do not.
#include "glint/mesh/mesh_reader_side.h"

#include <malloc.h>
#include <sys/resource.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <string>
#include <string_view>
#include <system_error>

#include <fmt/format.h>

#include "glint/mesh/assimp_import.h"
#include "glint/mesh/import_child.h"
#include "glint/mesh/mesh_reader_wire.h"
#include "glint/mesh/mesh_size_estimate.h"

namespace glint {

namespace wire {

bool writeMeshFile(int fd, const MeshFile& file) {
  bool ok = writeValue(fd, 'M') && writeValue(fd, std::uint64_t{file.droppedTriangles}) &&
            writeValue(fd, std::uint64_t{file.importerDroppedFaces ? 1u : 0u}) &&
            writeValue(fd, std::uint64_t{file.exactPositionNormalParts}) &&
            writeValue(fd, std::uint64_t{file.crowdedNormalPositions}) &&
            writeValue(fd, std::uint64_t{file.ignoredTextures.size()});
  for (const std::string& ignored : file.ignoredTextures) {
    ok = ok && writeMessage(fd, 'I', ignored);
  }
  ok = ok && writeValue(fd, std::uint64_t{file.missingMaterialLibraries.size()});
  for (const std::string& library : file.missingMaterialLibraries) {
    ok = ok && writeMessage(fd, 'L', library);
  }
  ok = ok && writeMessage(fd, 'F', file.fallbackMaterialLibrary);
  ok = ok && writeValue(fd, std::uint64_t{file.materials.size()});
  for (const MeshMaterial& m : file.materials) {
    ok = ok && writeMessage(fd, 'N', m.name) && writeValue(fd, m.material) &&
         writeValue(fd, m.emission) && writeValue(fd, static_cast<char>(m.fromFile));
    for (const MeshTexture& t : m.textures) {
      ok = ok && writeMessage(fd, 'T', t.file) && writeValue(fd, t.embedded);
    }
  }
  ok = ok && writeValue(fd, std::uint64_t{file.embeddedImages.size()});
  for (const std::vector<std::uint8_t>& image : file.embeddedImages) {
    ok = ok && writeVector(fd, image);
  }
  ok = ok && writeValue(fd, std::uint64_t{file.parts.size()});
  for (const TriangleMesh& part : file.parts) {
    ok = ok && writeValue(fd, part.materialIndex) && writeValue(fd, part.emission) &&
         writeVector(fd, part.positions) && writeVector(fd, part.normals) &&
         writeVector(fd, part.indices) && writeVector(fd, part.uvs);
  }
  return ok;
}

}  // namespace wire

namespace {

#if defined(__SANITIZE_ADDRESS__)
#define GLINT_READER_UNDER_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define GLINT_READER_UNDER_ASAN 1
#endif
#endif

// Caps this process's address space at what it uses now plus 512 MiB plus 256 bytes per byte of
// the mesh file (for a .gltf, of it and its buffer files). assimp's ASCII PLY reader takes any
// list count and reads zeros past the file's end: a 383-byte file's count of 44294967295 had it
// fill gigabytes for the whole 30 s limit; a 577-byte .gltf whose sparse accessor claims 40
// million vertices took 3 GB. With the cap such a file fails in a fraction of a second
// (std::bad_alloc, "not enough memory"); real files need far less (a 100 MB binary PLY, 25 GB
// allowed). Not under AddressSanitizer, whose shadow memory reserves terabytes of address space
// (the fuzzers bound the reader's time instead: setMeshReadTimeLimitForTesting).
void capAddressSpace([[maybe_unused]] const std::filesystem::path& file,
                     [[maybe_unused]] std::string_view extension,
                     [[maybe_unused]] const ReferencedFileRule& rule) {
#ifndef GLINT_READER_UNDER_ASAN
  std::error_code error;
  std::uintmax_t size = std::filesystem::file_size(file, error);
  if (error) return;
  if (extension == ".gltf") size = gltfBytes(file, size, rule);
  long pages = 0;
  if (std::FILE* statm = std::fopen("/proc/self/statm", "r")) {
    if (std::fscanf(statm, "%ld", &pages) != 1) pages = 0;
    std::fclose(statm);
  }
  if (pages <= 0) return;
  const double cap = static_cast<double>(pages) * static_cast<double>(::sysconf(_SC_PAGESIZE)) +
                     kMeshReaderMemoryBaseBytes +
                     kMeshReaderMemoryPerFileByte * static_cast<double>(size);
  if (!(cap < 0x1p62)) return;
  const auto bytes = static_cast<rlim_t>(cap);
  const rlimit limit{bytes, bytes};
  ::setrlimit(RLIMIT_AS, &limit);
#endif
}

}  // namespace

int runMeshReader(int argc, char** argv) {
  // Arguments (importMeshInChild): protocol, answer pipe, answer file (-1: none), delay in ms,
  // extension, scene folder, mesh file.
  if (argc != 8) {
    std::fprintf(stderr, "%s: glint starts this program to read mesh files; it is not run alone\n",
                 argc > 0 ? argv[0] : kMeshReaderProgram);
    return 2;
  }
  const int pipe = std::atoi(argv[2]);
  const int answer = std::atoi(argv[3]);
  if (std::string_view(argv[1]) != wire::kMeshReaderProtocol) {
    wire::writeMessage(
        pipe, 'E',
        fmt::format("cannot read it: the mesh reader {} is from another glint build ({}, "
                    "not {})",
                    argv[0], argv[1], wire::kMeshReaderProtocol));
    return 2;
  }
  // Large blocks from the heap rather than each from its own mmap: assimp's OBJ reader and the
  // post-processing free buffers of megabytes (the file, a line buffer of the file's size, the
  // meshes PreTransformVertices replaces) that later ones then reuse instead of faulting in
  // fresh pages (~4 ms of a 100k-triangle OBJ). 32 MiB is the most glibc accepts. The program
  // ends with _exit, so its heap is never given back in any case.
  ::mallopt(M_MMAP_THRESHOLD, 32 << 20);
  if (const long delay = std::atol(argv[4]); delay > 0) {
    const timespec pause{static_cast<time_t>(delay / 1000), (delay % 1000) * 1000000};
    ::nanosleep(&pause, nullptr);
  }
  const std::filesystem::path path = argv[7];
  const ReferencedFileRule rule(path, argv[6]);
  capAddressSpace(path, argv[5], rule);
  MeshFile result;
  std::string error;
  try {
    result = importMesh(path, argv[5], rule);
  } catch (const MeshLoadError& e) {
    error = e.what();
  } catch (...) {
    error = "invalid file: the mesh library failed reading it";
  }
  const auto send = [&](int fd) {
    return error.empty() ? wire::writeMeshFile(fd, result) : wire::writeMessage(fd, 'E', error);
  };
  if (answer >= 0 && send(answer)) {
    wire::writeValue(pipe, 'D');
    ::_exit(0);
  }
  // A partly written memory file would hold its pages until the parent closes it, after the
  // whole answer has come through the pipe as well: under the memory pressure that made the
  // write fail, give them back first.
  if (answer >= 0) static_cast<void>(::ftruncate(answer, 0));
  if (wire::writeValue(pipe, 'P')) send(pipe);
  ::_exit(0);
}

}  // namespace glint
