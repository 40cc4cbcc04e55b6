// A pre-check of JPEG marker segments before stb_image reads them.
#pragma once
#include <cstddef>

namespace gibake::gltf {

// For a JPEG (by its SOI marker, fill bytes allowed as stb allows them), whether the marker
// segments stb_image would read are sound: every length-prefixed segment fits in the file, and
// every DHT table has class 0 or 1, id 0..3, and 16 code counts summing to at most 256 and to no
// more than the segment still holds. stb_image builds a Huffman table from the counts into fixed
// 257-entry arrays without checking their sum, so a DHT whose counts sum past 256 writes past them
// (found by fuzz_import); such a file is refused before stb sees it, in stbi_info as in the decode.
// The walk follows stb's reader: entropy-coded data after SOS is skipped to the next marker
// that is neither a stuffed 0xFF00 nor a restart marker; where stb would stop reading (a
// marker it does not know, no marker where one must be, EOI) the walk stops and accepts.
// True for anything that is not a JPEG.
bool jpeg_segments_fit(const unsigned char* bytes, size_t size);

}  // namespace gibake::gltf
