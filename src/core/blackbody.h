// Blackbody emission colour (DESIGN §2 "Emission"): the Planck spectrum at temperature T divided
// by its own maximum (at Wien's peak, lambda = 2.8977721e-3 m·K / T, so B <= 1 everywhere),
// integrated against the CIE 1931 2° colour-matching functions normalised by ∫ȳ (a constant
// spectrum of 1 has Y = 1) and converted to linear Rec.709 (sRGB primaries, D65 white). This is
// pbrt-v4's normalised blackbody; T <= 100 K emits nothing.
//
// The CIE table comes from Debian's colord-data (cmake/cie_cmf.cmake); the integral runs over
// 360-830 nm in 1 nm steps with the 5 nm table interpolated linearly and Planck's law exact.
// Below about 1900 K the blackbody lies outside the Rec.709 gamut (its blue, then green,
// component turns negative): negative components are clamped to 0, since the renderer carries
// non-negative RGB radiance (blackbodyXyz keeps the unclamped colour).
//
// The GPU reads a table of this function (blackbodyTable, shaders/shared/blackbody.h): 4096
// entries spaced evenly in log T from 100 K to 1e6 K, linear in between, and beyond 1e6 K the
// last entry times (1e6 / T)^4 (the normalised spectrum's Rayleigh-Jeans limit), so no
// temperature is capped. tests/test_blackbody.cpp bounds the table's error against this function.
#pragma once

#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include <vector>

namespace plume {

constexpr double kWienDisplacement = 2.8977721e-3;  // m·K
constexpr double kBlackbodyMinKelvin = 100.0;        // T <= this emits nothing

// Planck's spectral radiance B(lambda, T), W·sr^-1·m^-3 (lambda in metres).
double planck(double lambdaMetres, double kelvin);
// ∫ȳ(λ) dλ over the table, nm (the CIE value is 106.857).
double cieYIntegral();
// The normalised blackbody in CIE XYZ (unclamped); 0 for T <= 100 K.
glm::dvec3 blackbodyXyz(double kelvin);
// Linear Rec.709 from CIE XYZ (D65, no adaptation).
glm::dvec3 xyzToRec709(const glm::dvec3& xyz);
// The normalised blackbody in linear Rec.709, negative components clamped to 0; 0 for T <= 100 K.
glm::dvec3 blackbodyRgb(double kelvin);
// The GPU's table (shaders/shared/blackbody.h BB_TABLE_*): entry i is blackbodyRgb at
// bb_table_kelvin(i), alpha 0.
std::vector<glm::vec4> blackbodyTable();

}  // namespace plume
