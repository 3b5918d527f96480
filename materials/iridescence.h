// The thin-film Fresnel term of KHR_materials_iridescence: a film of index `filmIor` and thickness
// d (nm) over a base whose normal-incidence reflectance is `baseF0`, seen at cos theta_1 from a
// medium of index `outsideIor` (1, or 1.5 under a clearcoat). Belcour & Barla 2017, "A Practical
// Extension to Microfacet Theory for the Modeling of Varying Iridescence" (ACM TOG 36(4)): the
// Airy summation of the film's inter-reflections, integrated over the spectrum analytically in
// Fourier space (their section 4) with Gaussian fits of the CIE XYZ sensitivities; in the
// approximation the extension's implementation notes give: Schlick reflectances per interface,
// phase shifts of 0 or pi, the first two Fourier terms, XYZ to linear Rec. 709; the result
// clamped to [0, 1] (the extension clamps at 0 only; the truncated series overshoots 1 slightly).
#pragma once

#include "core/math.h"

namespace ember {

Color thinFilmFresnel(float outsideIor, float filmIor, float cosTheta1, float thicknessNm,
                      const Color& baseF0);

}  // namespace ember
