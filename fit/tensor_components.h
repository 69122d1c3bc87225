// The six components of an inertia tensor in the one order used everywhere: the tensor fit, the
// attitude plan, results.json keys ("Ixx_kg_m2", ...), export and the report. Plain C++ (no
// Eigen), so the plan's header stays light.
#pragma once

namespace bifilar {

constexpr int kTensorComponents = 6;
enum TensorComponent { kIxx = 0, kIyy, kIzz, kIxy, kIxz, kIyz };
const char* TensorComponentName(int component);  // "Ixx", "Iyy", "Izz", "Ixy", "Ixz", "Iyz"; "?"

}  // namespace bifilar
