// gravcal: the 9-parameter error model of Farago, Maczak & Gingl (2024).
//
// Measured v, calibrated a = K (v + o) with lower-triangular K (paper Eq. 7-9):
//   a_x = k_xx (v_x + o_x)
//   a_y = k_xy (v_x + o_x) + k_yy (v_y + o_y)
//   a_z = k_xz (v_x + o_x) + k_yz (v_y + o_y) + k_zz (v_z + o_z)
// Parameter order p = (k_xx, k_yy, k_zz, k_xy, k_xz, k_yz, o_x, o_y, o_z),
// start p0 = (1, 1, 1, 0, 0, 0, 0, 0, 0) (paper Eq. 6). The model is applied
// here only: apply_model() (this model), apply_model_ggir() (GGIR's, in
// GGIR's arithmetic).
//
// Header-only, standard headers only, no heap: builds for a microcontroller.
// T is any number type with + - * / (double, float, or gravcal's fixed point).
#ifndef GRAVCAL_MODEL_HPP
#define GRAVCAL_MODEL_HPP

#include "gravcal/mcu/fp_contract.hpp"

namespace gravcal {

enum Param { KXX = 0, KYY = 1, KZZ = 2, KXY = 3, KXZ = 4, KYZ = 5,
             OX = 6, OY = 7, OZ = 8, NPARAM = 9 };

template <typename T>
struct Vec3 {
  T x, y, z;
};

// The identity calibration p0.
template <typename T>
inline void identity_params(T* p) {
  for (int i = 0; i < NPARAM; ++i) p[i] = T(0);
  p[KXX] = T(1);
  p[KYY] = T(1);
  p[KZZ] = T(1);
}

// a = K (v + o): from measured to calibrated.
template <typename T>
inline Vec3<T> apply_model(const T* p, const Vec3<T>& v) {
  const T ux = v.x + p[OX];
  const T uy = v.y + p[OY];
  const T uz = v.z + p[OZ];
  return Vec3<T>{p[KXX] * ux,
                 p[KXY] * ux + p[KYY] * uy,
                 p[KXZ] * ux + p[KYZ] * uy + p[KZZ] * uz};
}

// GGIR's model (van Hees et al. 2014: K diagonal, plus a temperature
// term), one axis, in the operation order of GGIR's R code:
//   a = (v + o) / (1 / s) + t / (1 / to),  t = temperature - mean temperature.
// Not the same bits as s (v + o) + t to: this is the named form wherever
// GGIR's numbers are promised to the bit (icp.hpp).
template <typename T>
inline T apply_model_ggir(T v, T o, T s, T t, T to) {
  return (v + o) / (T(1) / s) + t / (T(1) / to);
}

// v = K^-1 a - o: from true to measured, by forward substitution.
// The paper's Eq. 19 has sign slips (c_x - o_x, then c_x + o_x); this is the
// exact inverse of apply_model().
template <typename T>
inline Vec3<T> invert_model(const T* p, const Vec3<T>& a) {
  const T ux = a.x / p[KXX];
  const T uy = (a.y - p[KXY] * ux) / p[KYY];
  const T uz = (a.z - p[KXZ] * ux - p[KYZ] * uy) / p[KZZ];
  return Vec3<T>{ux - p[OX], uy - p[OY], uz - p[OZ]};
}

template <typename T>
inline T norm2(const Vec3<T>& a) {
  return a.x * a.x + a.y * a.y + a.z * a.z;
}

}  // namespace gravcal

#endif  // GRAVCAL_MODEL_HPP
