// The fiblet codec's use of the .fbl container: codec parameters <-> header
// fields, and the "source" section (what the input was, so that decompress
// can write back the same kind of file).
#pragma once

#include <string>
#include <string_view>

#include "codec/codec_params.h"
#include "codec/fbl_file.h"
#include "core/tractogram.h"

namespace fibscope {

// Version of the fiblet record encoding stored in FblHeaderFields::codec_version.
inline constexpr uint32_t kFibletCodecVersion = 1;

// Header fields for `params` (counts left 0). The header stores mm per
// normalised unit (1 / params.scale), in double.
FblHeaderFields fblHeaderFor(const CodecParams& params);

// The parameters a file was encoded with. Throws Error naming `path` when
// the codec version is not kFibletCodecVersion, the record size does not
// match N, or a value is out of range (validateCodecParams). Safe on
// untrusted headers.
CodecParams codecParamsFromFbl(const FblHeaderFields& fields, const std::string& path);

// The parameters as they will be after a trip through the header: the
// scale goes through 1/x in double twice. The compressor encodes with these,
// so encoder and decoder of the file use bit-identical values.
CodecParams roundTripThroughFbl(const CodecParams& params);

// JSON text of the "source" section: input path, format, declared counts,
// voxel space, header properties (tck keys, trk fields, TRX extras), and the
// names/components/dtypes of the per-streamline arrays stored as "dps/<name>"
// sections and of the per-point arrays stored as "dpv/<name>" sections
// (header.per_point), and those of `dropped_per_point` (arrays of the input
// that were not stored, for `info`).
std::string fblSourceJson(const TractogramHeader& header, const std::vector<DataArray>& dropped_per_point = {});

// The header of a decompressed tractogram, from the "source" JSON: format,
// space, properties, per-streamline and stored per-point array
// descriptions of the original; path = `fbl_path`, file_bytes 0, declared
// counts -1. Throws Error naming `fbl_path` when the JSON
// is malformed or a field has the wrong type.
TractogramHeader headerFromFblSource(std::string_view json, const std::string& fbl_path);

}  // namespace fibscope
