#include "materials/iridescence.h"

#include "materials/microfacet.h"

namespace ember {

namespace {

// ((n_t - n_i) / (n_t + n_i))^2: the reflectance at normal incidence between two indices.
float iorToF0(float transmitted, float incident) {
  const float r = (transmitted - incident) / (transmitted + incident);
  return r * r;
}

// The inverse for a base seen from air, used for dielectrics and metals alike (a metal's
// extinction cannot be recovered from its f0 and is taken as 0, as the extension says).
Color f0ToIor(const Color& f0) {
  const Color s = glm::sqrt(glm::clamp(f0, Color(0.0f), Color(0.9999f)));
  return (Color(1.0f) + s) / (Color(1.0f) - s);
}

// The m-th Fourier term of the XYZ sensitivities at optical path difference `opd` (nm) and phase
// `shift`, in linear Rec. 709 RGB (Belcour & Barla 2017, section 4, with their Gaussian fits).
Color sensitivity(float opd, const Color& shift) {
  const double phase = 2.0 * double(kPi) * double(opd) * 1e-9;
  const double val[3] = {5.4856e-13, 4.4201e-13, 5.2481e-13};
  const double pos[3] = {1.6810e+06, 1.7953e+06, 2.2084e+06};
  const double var[3] = {4.3278e+09, 9.3046e+09, 6.6121e+09};
  double xyz[3];
  for (int k = 0; k < 3; ++k)
    xyz[k] = val[k] * std::sqrt(2.0 * kPi * var[k]) * std::cos(pos[k] * phase + shift[k]) *
             std::exp(-phase * phase * var[k]);
  xyz[0] += 9.7470e-14 * std::sqrt(2.0 * kPi * 4.5282e+09) * std::cos(2.2399e+06 * phase + shift[0]) *
            std::exp(-4.5282e+09 * phase * phase);
  for (double& v : xyz) v /= 1.0685e-7;
  // XYZ to linear Rec. 709 (sRGB primaries, D65).
  return Color(float(3.2404542 * xyz[0] - 1.5371385 * xyz[1] - 0.4985314 * xyz[2]),
               float(-0.9692660 * xyz[0] + 1.8760108 * xyz[1] + 0.0415560 * xyz[2]),
               float(0.0556434 * xyz[0] - 0.2040259 * xyz[1] + 1.0572252 * xyz[2]));
}

}  // namespace

Color thinFilmFresnel(float outsideIor, float filmIor, float cosTheta1, float thicknessNm,
                      const Color& baseF0) {
  // A film thinning to nothing fades into the outside medium (the Khronos sample viewer's
  // smoothstep over the first 30 nm), so that zero thickness is no film at all.
  const float t = std::clamp(thicknessNm / 30.0f, 0.0f, 1.0f);
  const float eta2 = outsideIor + (filmIor - outsideIor) * t * t * (3.0f - 2.0f * t);
  const float cos1 = std::clamp(std::abs(cosTheta1), 0.0f, 1.0f);
  // Snell into the film; total internal reflection there reflects everything.
  const float sin2Sq = (outsideIor / eta2) * (outsideIor / eta2) * (1.0f - cos1 * cos1);
  if (sin2Sq >= 1.0f) return Color(1.0f);
  const float cos2 = std::sqrt(1.0f - sin2Sq);

  // First interface (outside to film), Schlick; R21 = R12, T121 = 1 - R12.
  const float r12 = schlickFresnel(iorToF0(eta2, outsideIor), cos1);
  const float t121 = 1.0f - r12;
  // Second interface (film to base).
  const Color baseIor = f0ToIor(baseF0 + Color(0.0001f));
  Color r23;
  for (int k = 0; k < 3; ++k) r23[k] = schlickFresnel(iorToF0(baseIor[k], eta2), cos2);

  // Phase shifts of pi where light meets a lower index, 0 otherwise (polarisation ignored).
  const float phi12 = eta2 < outsideIor ? kPi : 0.0f;
  const float phi21 = kPi - phi12;
  Color phi;
  for (int k = 0; k < 3; ++k) phi[k] = phi21 + (baseIor[k] < eta2 ? kPi : 0.0f);

  // The optical path difference of one round trip through the film.
  const float opd = 2.0f * eta2 * thicknessNm * cos2;
  const Color r123 = glm::clamp(r12 * r23, Color(1e-5f), Color(0.9999f));
  const Color sqrtR123 = glm::sqrt(r123);
  const Color rs = t121 * t121 * r23 / (Color(1.0f) - r123);
  Color intensity = r12 + rs;  // the DC term
  Color cm = rs - Color(t121);
  for (int m = 1; m <= 2; ++m) {
    cm *= sqrtR123;
    intensity += cm * 2.0f * sensitivity(float(m) * opd, float(m) * phi);
  }
  // The extension clamps below at 0; the two-term series also overshoots 1 by a few percent at some
  // thicknesses, which would make the film reflect more than it receives: clamped there too.
  return glm::clamp(intensity, Color(0.0f), Color(1.0f));
}

}  // namespace ember
