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

std::vector<std::uint8_t> NpyHeader(const NpyArray& array) {
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
  return out;
}

std::vector<std::uint8_t> NpyBytes(const NpyArray& array) {
  std::vector<std::uint8_t> out = NpyHeader(array);
  out.insert(out.end(), array.bytes.begin(), array.bytes.end());
  return out;
}

std::uint32_t Crc32(const std::uint8_t* data, std::size_t size, std::uint32_t crc) {
  // zlib's table-driven CRC-32, in pieces that fit its uInt length
  uLong c = crc;
  while (size > 0) {
    const auto n = static_cast<uInt>(std::min<std::size_t>(size, 1u << 30));
    c = crc32(c, data, n);
    data += n;
    size -= n;
  }
  return static_cast<std::uint32_t>(c);
}

void WriteNpz(const std::string& path, const std::vector<NpyArray>& arrays) {
  // the archive's headers are assembled here; each array's bytes go to the file from where they
  // are, without a copy
  std::ofstream f(path, std::ios::binary);
  auto write = [&f](const std::uint8_t* data, std::size_t size) {
    f.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  };
  std::vector<std::uint8_t> local, central;
  std::size_t offset = 0;
  for (const NpyArray& a : arrays) {
    const std::vector<std::uint8_t> header = NpyHeader(a);
    const std::size_t bytes = header.size() + a.bytes.size();
    if (bytes >= 0xFFFFFFFFu) throw Error("npz: array '" + a.name + "' is over 4 GB");
    if (offset >= 0xFFFFFFFFu) throw Error("npz: '" + path + "' is over 4 GB");
    const std::string file = a.name + ".npy";
    const std::uint32_t crc =
        Crc32(a.bytes.data(), a.bytes.size(), Crc32(header.data(), header.size()));
    const auto size = static_cast<std::uint32_t>(bytes);
    // local file header: stored, no data descriptor, a fixed date (1980-01-01) for equal bytes
    local.clear();
    Put32(&local, 0x04034b50);
    for (std::uint32_t v : {20u, 0u, 0u, 0u, 0x21u}) Put16(&local, v);
    Put32(&local, crc);
    Put32(&local, size);
    Put32(&local, size);
    Put16(&local, static_cast<std::uint32_t>(file.size()));
    Put16(&local, 0);
    local.insert(local.end(), file.begin(), file.end());
    local.insert(local.end(), header.begin(), header.end());
    write(local.data(), local.size());
    write(a.bytes.data(), a.bytes.size());
    // its central directory entry
    Put32(&central, 0x02014b50);
    for (std::uint32_t v : {20u, 20u, 0u, 0u, 0u, 0x21u}) Put16(&central, v);
    Put32(&central, crc);
    Put32(&central, size);
    Put32(&central, size);
    Put16(&central, static_cast<std::uint32_t>(file.size()));
    for (std::uint32_t v : {0u, 0u, 0u, 0u}) Put16(&central, v);
    Put32(&central, 0);
    Put32(&central, static_cast<std::uint32_t>(offset));
    central.insert(central.end(), file.begin(), file.end());
    offset += local.size() + a.bytes.size();
  }
  if (offset >= 0xFFFFFFFFu) throw Error("npz: '" + path + "' is over 4 GB");
  std::vector<std::uint8_t> end = central;
  Put32(&end, 0x06054b50);
  Put16(&end, 0);
  Put16(&end, 0);
  Put16(&end, static_cast<std::uint32_t>(arrays.size()));
  Put16(&end, static_cast<std::uint32_t>(arrays.size()));
  Put32(&end, static_cast<std::uint32_t>(central.size()));
  Put32(&end, static_cast<std::uint32_t>(offset));
  Put16(&end, 0);
  write(end.data(), end.size());
  if (!f) throw Error("npz: cannot write '" + path + "'");
}

}  // namespace partsim::vision::internal
