// An image texture filtered over each hit's footprint ("filter": "trilinear" in a scene file):
// OpenImageIO's TextureSystem (through the image plugin, io/image_plugin.h) looks it up between
// the two MIP levels whose texels are nearest the footprint's width, bilinearly within each. The
// footprint is the hit's SurfaceHit::uvFootprint (Camera::footprintAt), so the image is no longer
// the pixel integral of the unfiltered texture: filtering trades that bias for less aliasing at
// low sample counts, which is why it is opt-in (docs/scene-format.md).
#pragma once

#include "io/image_plugin.h"
#include "materials/texture.h"

#include <string>
#include <vector>

namespace ember {

// The first failed lookup of any filtered texture in this process ("" if none), naming its file:
// a texture file that disappears or changes while a render reads it from the texture cache. A
// lookup that fails returns black; the render command then reports this and writes nothing.
std::string filteredTextureFailure();
// The same, and forgets it: a process that renders again (the Python module) reports each render's.
std::string takeFilteredTextureFailure();

class FilteredImageTexture final : public Texture {
 public:
  // `texels`: linear, rows from the top. Throws InputError(`name`: ...) if the texture system
  // cannot take the image.
  FilteredImageTexture(const ImagePlugin& plugin, const std::string& name, int width, int height,
                       const std::vector<Color>& texels, TextureWrap wrap, const Color& scale)
      : FilteredImageTexture(plugin, name, width, height, texels, wrap, wrap, scale) {}
  // wrapS along the width, wrapT along the rows (glTF samplers).
  FilteredImageTexture(const ImagePlugin& plugin, const std::string& name, int width, int height,
                       const std::vector<Color>& texels, TextureWrap wrapS, TextureWrap wrapT,
                       const Color& scale);
  // A texture looked up straight from its file (ImagePlugin::addTextureFile: tiles read on demand,
  // within the texture cache), already opened as `handle` with `info`'s bounds.
  FilteredImageTexture(const ImagePlugin& plugin, const std::string& name, const void* handle,
                       const ImagePlugin::TextureFile& info, TextureWrap wrap, const Color& scale);
  FilteredImageTexture(const FilteredImageTexture&) = delete;
  FilteredImageTexture& operator=(const FilteredImageTexture&) = delete;

  // Without a footprint: the finest level, bilinearly (what a lookup from a light sample gets).
  Color eval(Vec2 uv) const override { return lookup(uv, 0.0f); }
  Color evalAt(const SurfaceHit& hit) const override;
  Color evalFresh(const SurfaceHit& hit) const override { return lookup(hit.uv, hit.uvFootprint); }
  Color evalFootprint(Vec2 uv, float width) const override { return lookup(uv, width); }
  Color maxValue() const override { return max_; }
  Color minValue() const override { return min_; }
  Color average() const override { return average_; }
  bool mayBeBlack() const override { return mayBeBlack_; }

 private:
  Color lookup(Vec2 uv, float width) const;

  const ImagePlugin& plugin_;
  std::string name_;        // the file, for filteredTextureFailure
  std::vector<float> rgb_;  // what the texture system reads, from memory (empty: from the file)
  const void* handle_;
  ImagePlugin::Wrap wrapS_, wrapT_;
  Color scale_;
  Color max_{0.0f}, min_{0.0f}, average_{0.0f};
  bool mayBeBlack_ = false;
  uint64_t id_;  // evalAt's memo key (materials/hit_memo.h)
};

}  // namespace ember
