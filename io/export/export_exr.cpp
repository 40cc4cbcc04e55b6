// EXR export (see export_exr.h). OpenEXR includes stay in this file.
#include "io/export/export_exr.h"

#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfOutputFile.h>
#include <sys/stat.h>

#include <cerrno>
#include <cstring>

#include "io/output/bake_atomic.h"

namespace gibake {
namespace {

struct Image {
  int width = 0, height = 0;
  std::vector<std::string> channels;
  std::vector<std::vector<float>> planes;  // one per channel, width*height
  void init(int w, int h, std::vector<std::string> names) {
    width = w;
    height = h;
    channels = std::move(names);
    planes.assign(channels.size(), std::vector<float>(size_t(w) * size_t(h), 0.f));
  }
};

Status write_exr(const std::string& path, const Image& image) {
  AtomicFile file;
  GIBAKE_TRY(file.begin(path));
  try {
    Imf::Header header(image.width, image.height);
    for (const std::string& name : image.channels) header.channels().insert(name, Imf::Channel(Imf::FLOAT));
    Imf::OutputFile out(file.temp_path().c_str(), header);
    Imf::FrameBuffer frame;
    for (size_t c = 0; c < image.channels.size(); ++c)
      frame.insert(image.channels[c],
                   Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(const_cast<float*>(image.planes[c].data())),
                              sizeof(float), sizeof(float) * size_t(image.width)));
    out.setFrameBuffer(frame);
    out.writePixels(image.height);
  } catch (const std::exception& e) {
    return Status::io(path, std::string("OpenEXR: ") + e.what());
  }
  return file.commit();
}

// An atlas as an image: channel k of the picture is component k of texel_of(x, y).
template <class TexelOf>
Image atlas_image(uint32_t width, uint32_t height, std::vector<std::string> channels, TexelOf texel_of) {
  Image img;
  img.init(int(width), int(height), std::move(channels));
  for (uint32_t y = 0; y < height; ++y)
    for (uint32_t x = 0; x < width; ++x) {
      const auto t = texel_of(x, y);
      for (size_t k = 0; k < img.channels.size(); ++k) img.planes[k][size_t(y) * width + x] = t[k];
    }
  return img;
}

Image irradiance_image(const loader::DdgiVolume& v) {
  const gibake_ddgi_volume& d = v.desc();
  return atlas_image(d.irradiance_width, d.irradiance_height, {"R", "G", "B", "A"},
                     [&](uint32_t x, uint32_t y) { return v.irradiance_texel(x, y); });
}

Image depth_image(const loader::DdgiVolume& v) {
  const gibake_ddgi_volume& d = v.desc();
  return atlas_image(d.depth_width, d.depth_height, {"R", "G"},
                     [&](uint32_t x, uint32_t y) { return v.depth_texel(x, y); });
}

Image sh_image(const loader::DdgiVolume& v) {
  Image img;
  const gibake_ddgi_volume& d = v.desc();
  std::vector<std::string> names;
  for (uint32_t c = 0; c < d.sh_coefficients; ++c)
    for (const char* ch : {"R", "G", "B"}) names.push_back("c" + std::to_string(c) + "." + ch);
  const int width = d.counts[0] * d.counts[1];
  img.init(width, d.counts[2], names);
  for (uint32_t p = 0; p < v.probe_count(); ++p) {
    const auto c = v.probe_coord(p);
    const size_t pixel = size_t(c[2]) * size_t(width) + size_t(c[0] + d.counts[0] * c[1]);
    for (uint32_t k = 0; k < d.sh_coefficients * 3; ++k) img.planes[k][pixel] = v.sh(p, k / 3, k % 3);
  }
  return img;
}

Status ensure_dir(const std::string& dir) {
  struct stat st;
  if (stat(dir.c_str(), &st) == 0) return S_ISDIR(st.st_mode) ? Status::ok() : Status::io(dir, "not a folder");
  if (mkdir(dir.c_str(), 0777) != 0) return Status::io(dir, std::string("cannot create folder: ") + std::strerror(errno));
  return Status::ok();
}

}  // namespace

namespace {

// Volume v's images by name, in the order they are written: the header's list.
std::vector<std::string> image_names(const loader::DdgiVolume& volume) {
  std::vector<std::string> names;
  if (volume.has_irradiance()) names.push_back("irradiance");
  if (volume.has_depth()) names.push_back("depth");
  names.push_back("sh");
  return names;
}

std::string image_path(const std::string& dir, const std::string& name, size_t volume) {
  return dir + "/" + name + (volume == 0 ? "" : "_" + std::to_string(volume)) + ".exr";
}

}  // namespace

std::vector<std::string> exr_file_paths(const loader::BakeFile& file, const std::string& dir) {
  std::vector<std::string> paths;
  for (size_t i = 0; i < file.ddgi_volumes().size(); ++i)
    for (const std::string& name : image_names(file.ddgi_volumes()[i])) paths.push_back(image_path(dir, name, i));
  return paths;
}

Status export_exr(const loader::BakeFile& file, const std::string& dir, std::vector<std::string>* written) {
  GIBAKE_TRY(ensure_dir(dir));
  const auto& volumes = file.ddgi_volumes();
  if (volumes.empty()) return Status::invalid("", "export", "the bake file has no DDGI volume");
  for (size_t i = 0; i < volumes.size(); ++i)
    for (const std::string& name : image_names(volumes[i])) {
      const Image image = name == "irradiance" ? irradiance_image(volumes[i])
                          : name == "depth"    ? depth_image(volumes[i])
                                               : sh_image(volumes[i]);
      const std::string path = image_path(dir, name, i);
      GIBAKE_TRY(write_exr(path, image));
      if (written) written->push_back(path);
    }
  return Status::ok();
}

}  // namespace gibake
