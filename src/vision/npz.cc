// .npy and .npz writing (the zip container: local headers, stored entries, central directory).
#include "vision/npz.h"

#include <zlib.h>

#include <algorithm>
#include <array>
#include <cstring>
#include <fstream>

#include "partsim/core/error.h"

namespace partsim::vision::internal {

namespace {

template <typename T>
NpyArray Make(const std::string& name, const char* descr, const std::vector<T>& values,
              const std::vector<std::size_t>& shape) {
  std::size_t n = 1;
  for (std::size_t s : shape) n *= s;
  if (n != values.size())
    throw Error("npz: array '" + name + "' has " + std::to_string(values.size()) +
                " values for a shape of " + std::to_string(n));
  NpyArray a;
  a.name = name;
  a.descr = descr;
  a.shape = shape;
  a.bytes.resize(values.size() * sizeof(T));
  if (!values.empty()) std::memcpy(a.bytes.data(), values.data(), a.bytes.size());
  return a;
}

void Put16(std::vector<std::uint8_t>* out, std::uint32_t v) {
  out->push_back(static_cast<std::uint8_t>(v & 0xff));
  out->push_back(static_cast<std::uint8_t>((v >> 8) & 0xff));
}

void Put32(std::vector<std::uint8_t>* out, std::uint32_t v) {
  Put16(out, v & 0xffff);
  Put16(out, v >> 16);
}

}  // namespace

NpyArray MakeNpyArray(const std::string& name, const std::vector<float>& values,
                      const std::vector<std::size_t>& shape) {
  return Make(name, "<f4", values, shape);
}
NpyArray MakeNpyArray(const std::string& name, const std::vector<std::int32_t>& values,
                      const std::vector<std::size_t>& shape) {
  return Make(name, "<i4", values, shape);
}
NpyArray MakeNpyArray(const std::string& name, const std::vector<std::uint8_t>& values,
                      const std::vector<std::size_t>& shape) {
  return Make(name, "|u1", values, shape);
}

std::vector<std::uint8_t> NpyBytes(const NpyArray& array) {
  std::string shape = "(";
  for (std::size_t i = 0; i < array.shape.size(); ++i)
    shape += std::to_string(array.shape[i]) + (array.shape.size() == 1      ? ","
                                               : i + 1 < array.shape.size() ? ", "
                                                                            : "");
  shape += ")";
  std::string header =
      "{'descr': '" + array.descr + "', 'fortran_order': False, 'shape': " + shape + ", }";
  // magic (6) + version (2) + length (2) + header + padding + '\n', a multiple of 64
  const std::size_t total = 10 + header.size() + 1;
  header += std::string((64 - total % 64) % 64, ' ') + "\n";
  std::vector<std::uint8_t> out = {0x93, 'N', 'U', 'M', 'P', 'Y', 1, 0};
  Put16(&out, static_cast<std::uint32_t>(header.size()));
  out.insert(out.end(), header.begin(), header.end());
  out.insert(out.end(), array.bytes.begin(), array.bytes.end());
  return out;
}

std::uint32_t Crc32(const std::uint8_t* data, std::size_t size) {
  // zlib's table-driven CRC-32, in pieces that fit its uInt length
  uLong crc = crc32(0L, Z_NULL, 0);
  while (size > 0) {
    const auto n = static_cast<uInt>(std::min<std::size_t>(size, 1u << 30));
    crc = crc32(crc, data, n);
    data += n;
    size -= n;
  }
  return static_cast<std::uint32_t>(crc);
}

void WriteNpz(const std::string& path, const std::vector<NpyArray>& arrays) {
  std::vector<std::uint8_t> out, central;
  for (const NpyArray& a : arrays) {
    const std::vector<std::uint8_t> data = NpyBytes(a);
    if (data.size() >= 0xFFFFFFFFu) throw Error("npz: array '" + a.name + "' is over 4 GB");
    const std::string file = a.name + ".npy";
    const std::uint32_t crc = Crc32(data.data(), data.size());
    const auto size = static_cast<std::uint32_t>(data.size());
    const auto offset = static_cast<std::uint32_t>(out.size());
    // local file header: stored, no data descriptor, a fixed date (1980-01-01) for equal bytes
    Put32(&out, 0x04034b50);
    for (std::uint32_t v : {20u, 0u, 0u, 0u, 0x21u}) Put16(&out, v);
    Put32(&out, crc);
    Put32(&out, size);
    Put32(&out, size);
    Put16(&out, static_cast<std::uint32_t>(file.size()));
    Put16(&out, 0);
    out.insert(out.end(), file.begin(), file.end());
    out.insert(out.end(), data.begin(), data.end());
    // its central directory entry
    Put32(&central, 0x02014b50);
    for (std::uint32_t v : {20u, 20u, 0u, 0u, 0u, 0x21u}) Put16(&central, v);
    Put32(&central, crc);
    Put32(&central, size);
    Put32(&central, size);
    Put16(&central, static_cast<std::uint32_t>(file.size()));
    for (std::uint32_t v : {0u, 0u, 0u, 0u}) Put16(&central, v);
    Put32(&central, 0);
    Put32(&central, offset);
    central.insert(central.end(), file.begin(), file.end());
  }
  const auto central_offset = static_cast<std::uint32_t>(out.size());
  out.insert(out.end(), central.begin(), central.end());
  Put32(&out, 0x06054b50);
  Put16(&out, 0);
  Put16(&out, 0);
  Put16(&out, static_cast<std::uint32_t>(arrays.size()));
  Put16(&out, static_cast<std::uint32_t>(arrays.size()));
  Put32(&out, static_cast<std::uint32_t>(central.size()));
  Put32(&out, central_offset);
  Put16(&out, 0);
  std::ofstream f(path, std::ios::binary);
  f.write(reinterpret_cast<const char*>(out.data()), static_cast<std::streamsize>(out.size()));
  if (!f) throw Error("npz: cannot write '" + path + "'");
}

}  // namespace partsim::vision::internal
