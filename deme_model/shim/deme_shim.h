/* SPDX-License-Identifier: GPL-2.0-or-later
   stickslip: the few names of DEM-Engine's force kernels that deme_model/stick_slip.cu uses,
   for the CPU (g++), so that the same file is compiled and run on a machine without a GPU
   (tests/deme_shim.py). Written from DEM-Engine 3.0.19's kernel sources, by signature:
   float3/float4/double3 and make_float3/make_float4 (CUDA's vector types), the arithmetic of its
   CUDAMathHelpers.cuh (float3 + - and scalar * /, dot, cross, length; unary minus binds to
   an lvalue only, as there), applyOriQToVector3 and matProxy2ContactParam
   (DEMHelperKernels.cuh), and the constants of DEM/Defines.h the model reads. Every
   operation is one IEEE float operation, as on the GPU; the GPU may fuse a multiply and an
   add (FMA) where this does not (built with -ffp-contract=off), a difference of a rounding. */

#ifndef STICKSLIP_DEME_SHIM_H
#define STICKSLIP_DEME_SHIM_H

#include <cmath>
#include <cstdint>

struct float3 {
  float x, y, z;
};
struct float4 {
  float x, y, z, w;
};
struct double3 {
  double x, y, z;
};

inline float3 make_float3(float x, float y, float z) { return float3{x, y, z}; }
inline float4 make_float4(float x, float y, float z, float w) { return float4{x, y, z, w}; }

inline float3 operator+(float3 a, float3 b) { return make_float3(a.x + b.x, a.y + b.y, a.z + b.z); }
inline float3 operator-(float3 a, float3 b) { return make_float3(a.x - b.x, a.y - b.y, a.z - b.z); }
inline float3 operator*(float3 a, float b) { return make_float3(a.x * b, a.y * b, a.z * b); }
inline float3 operator*(float b, float3 a) { return make_float3(b * a.x, b * a.y, b * a.z); }
inline float3 operator/(float3 a, float b) { return make_float3(a.x / b, a.y / b, a.z / b); }
inline float3 operator-(float3 &a) { return make_float3(-a.x, -a.y, -a.z); }
inline void operator+=(float3 &a, float3 b) { a = a + b; }
inline void operator-=(float3 &a, float3 b) { a = a - b; }
inline float dot(float3 a, float3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline float3 cross(float3 a, float3 b)
{
  return make_float3(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}
inline float length(float3 v) { return sqrtf(dot(v, v)); }

// rotate v by the unit quaternion Q (x, y, z, w): the engine's local-to-global map
template <typename T1, typename T2> inline void applyOriQToVector3(T1 &v, const T2 &Q)
{
  const auto X = v.x, Y = v.y, Z = v.z;
  const auto w = Q.w, x = Q.x, y = Q.y, z = Q.z;
  v.x = (2 * (w * w + x * x) - 1) * X + (2 * (x * y - w * z)) * Y + (2 * (x * z + w * y)) * Z;
  v.y = (2 * (x * y + w * z)) * X + (2 * (w * w + y * y) - 1) * Y + (2 * (y * z - w * x)) * Z;
  v.z = (2 * (x * z - w * y)) * X + (2 * (y * z + w * x)) * Y + (2 * (w * w + z * z) - 1) * Z;
}

// effective Young's and shear moduli of a contact from each material's E and nu
template <typename T1> inline void matProxy2ContactParam(T1 &E_eff, T1 &G_eff, const T1 &Y1, const T1 &nu1,
                                                         const T1 &Y2, const T1 &nu2)
{
  const T1 invE = ((T1)1 - nu1 * nu1) / Y1 + ((T1)1 - nu2 * nu2) / Y2;
  E_eff = (T1)1 / invE;
  const T1 invG = (T1)2 * ((T1)2 - nu1) * ((T1)1 + nu1) / Y1 + (T1)2 * ((T1)2 - nu2) * ((T1)1 + nu2) / Y2;
  G_eff = (T1)1 / invG;
}

#define DEME_TINY_FLOAT 1e-12
#define DEME_HUGE_FLOAT 1e15

namespace deme {
typedef uint8_t contact_t;
typedef uint16_t materialsOffset_t;
typedef uint32_t bodyID_t;
constexpr double PI = 3.1415926535897932385;
constexpr double PI_SQUARED = 9.869604401089358;
// encodeType(A, B) = (A << 4) | B with sphere 1, triangle 2, analytical 4
constexpr contact_t NOT_A_CONTACT = 0;
constexpr contact_t SPHERE_SPHERE_CONTACT = (1 << 4) | 1;
constexpr contact_t SPHERE_TRIANGLE_CONTACT = (1 << 4) | 2;
constexpr contact_t SPHERE_ANALYTICAL_CONTACT = (1 << 4) | 4;
}  // namespace deme

#endif
