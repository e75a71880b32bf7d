// The Aggregate's queries compiled for x86-64-v4 (AVX-512 F, BW, CD, DQ, VL): aggregate.cpp's
// intersect, intersectPacket and transmittance as intersectAvx512, intersectPacketAvx512 and
// transmittanceAvx512, nothing else of it. The flags (src/CMakeLists.txt) add -march=x86-64-v4 in
// the optimised builds.
#define GLINT_AGGREGATE_KERNELS_ONLY
#define GLINT_ISA_KERNEL(name) name##Avx512
#include "glint/accel/aggregate.cpp"  // NOLINT(bugprone-suspicious-include)
