// The Aggregate's choice of kernels: the queries of each instruction set (aggregate.cpp).
#include "glint/accel/aggregate.h"

namespace glint {

const Aggregate::Kernels& Aggregate::kernelsFor(Isa isa) {
  static const Kernels kBaseline{&Aggregate::intersectBaseline, &Aggregate::transmittanceBaseline,
                                 &Aggregate::intersectPacketBaseline,
                                 &Aggregate::transmittancePacketBaseline, Isa::Baseline};
  static const Kernels kAvx2{&Aggregate::intersectAvx2, &Aggregate::transmittanceAvx2,
                             &Aggregate::intersectPacketAvx2,
                             &Aggregate::transmittancePacketAvx2, Isa::Avx2};
  static const Kernels kAvx512{&Aggregate::intersectAvx512, &Aggregate::transmittanceAvx512,
                               &Aggregate::intersectPacketAvx512,
                               &Aggregate::transmittancePacketAvx512, Isa::Avx512};
  switch (isa) {
    case Isa::Avx2:
      return kAvx2;
    case Isa::Avx512:
      return kAvx512;
    case Isa::Baseline:
      break;
  }
  return kBaseline;
}

void Aggregate::setIsa(Isa isa) {
  requireIsa(isa);
  kernels_ = &kernelsFor(isa);
}

}  // namespace glint
