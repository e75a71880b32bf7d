// The Aggregate's queries compiled for x86-64-v3 (AVX2, FMA, BMI2): aggregate.cpp's intersect,
// intersectPacket and transmittance as intersectAvx2, intersectPacketAvx2 and transmittanceAvx2,
// nothing else of it. The flags (src/CMakeLists.txt) add -march=x86-64-v3 in the optimised builds.
#define GLINT_AGGREGATE_KERNELS_ONLY
#define GLINT_ISA_KERNEL(name) name##Avx2
#include "glint/accel/aggregate.cpp"  // NOLINT(bugprone-suspicious-include)
