// The streamlines of a .tck read in place: each one's points are floats in
// the read buffer, not copied into a Tractogram. For passes that look at
// every point and keep few of them (`fibscope filter`: the reader's copy
// into a chunk and the filter's second copy of what it keeps were half of
// its time on a 279 MB tckgen file).
//
// One scan covers the streamlines that START in a byte range of the data,
// so a file split into ranges is scanned on every core at once: a range
// after the first begins after the first NaN separator at or after its
// start (the streamline running across the boundary belongs to the range
// before, which reads on past its end to finish it).
//
// Only what a whole, well-formed file holds is read: native float32 data
// whose last triplet is the Inf terminator. Anything else (a triplet mixing
// numbers with NaN/Inf, an Inf before the end, no terminator) stops the scan
// as Damaged, and the caller reads the file with the reader, which says
// what is wrong the way it always does (io/tck_reader.cpp).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "io/tck_format.h"

namespace fibscope {

// Whether a .tck can be scanned in place: native float32 samples, data a
// whole number of triplets ending in a NaN separator (or nothing) and the
// Inf terminator. `info` from parseTckHeader on `file`.
bool tckScannableInPlace(const MappedFile& file, const TckHeaderInfo& info);

class TckStreamlineScan {
 public:
  enum class Step { Streamline, Done, Damaged };

  // Scans the streamlines that start in [begin, stop) of the data `data`
  // reads, which begins at data_begin (begin, stop: a multiple of 12 bytes
  // from data_begin, stop may be data.end()); restarts `data` there and
  // reads it until the last of them ends.
  TckStreamlineScan(TrackDataStream& data, uint64_t data_begin, uint64_t begin, uint64_t stop);

  // The next streamline: points() and pointCount() hold it until the next
  // call. Done after the last streamline that starts before `stop` (or at
  // the terminator); Damaged at anything a well-formed file does not hold.
  Step next();
  const float* points() const { return points_; }
  size_t pointCount() const { return count_; }

 private:
  // Skips to the first streamline start at or after the range's beginning.
  Step skipToStart();
  // Finds the first non-finite triplet at the front, growing the buffer's
  // window until it is there (a streamline that outgrows the buffer goes
  // to long_ when `keep`, else is dropped: a skip); its sample index from
  // the front, or npos at the end of the data.
  size_t findSeparator(bool keep);

  TrackDataStream& data_;
  uint64_t stop_;
  bool started_ = false, done_ = false;
  std::vector<float> long_;  // a streamline longer than the read buffer
  const float* points_ = nullptr;
  size_t count_ = 0;
};

}  // namespace fibscope
