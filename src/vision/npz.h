// NumPy .npz archives (a zip of .npy arrays, stored without compression) for the datasets'
// point clouds: float32, int32 and uint8 arrays in C order. Not part of the public API.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace partsim::vision::internal {

/// One array of an archive: `name` (without ".npy"), NumPy dtype descr ("<f4", "<i4", "|u1"),
/// shape and the raw little-endian bytes.
struct NpyArray {
  std::string name;
  std::string descr;
  std::vector<std::size_t> shape;
  std::vector<std::uint8_t> bytes;
};

/// An array of float32, int32 or uint8 values.
NpyArray MakeNpyArray(const std::string& name, const std::vector<float>& values,
                      const std::vector<std::size_t>& shape);
NpyArray MakeNpyArray(const std::string& name, const std::vector<std::int32_t>& values,
                      const std::vector<std::size_t>& shape);
NpyArray MakeNpyArray(const std::string& name, const std::vector<std::uint8_t>& values,
                      const std::vector<std::size_t>& shape);

/// The header of an .npy file (format 1.0) holding `array`: what comes before its bytes.
std::vector<std::uint8_t> NpyHeader(const NpyArray& array);
/// The bytes of an .npy file (format 1.0) holding `array`.
std::vector<std::uint8_t> NpyBytes(const NpyArray& array);
/// Writes an .npz archive; throws partsim::Error naming the path when it cannot be written.
void WriteNpz(const std::string& path, const std::vector<NpyArray>& arrays);
/// CRC-32 (zip's, IEEE 802.3) of `size` bytes; `crc` is the CRC of bytes before them, so
/// that pieces chain: Crc32(b, nb, Crc32(a, na)) is the CRC of a then b.
std::uint32_t Crc32(const std::uint8_t* data, std::size_t size, std::uint32_t crc = 0);

}  // namespace partsim::vision::internal
