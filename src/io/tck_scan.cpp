#include "io/tck_scan.h"

#include <algorithm>

namespace fibscope {
namespace {

constexpr size_t kTriplet = 12;  // bytes of a float32 triplet
constexpr size_t kNone = size_t(-1);
const TckDataType kFloat32{"Float32LE", 4, false};

// The kind of the whole triplet at p, or nullopt when its samples differ.
std::optional<SampleKind> tripletKind(const uint8_t* p) {
  const SampleKind k = classifySample(p, kFloat32);
  if (classifySample(p + 4, kFloat32) != k || classifySample(p + 8, kFloat32) != k) return std::nullopt;
  return k;
}

}  // namespace

bool tckScannableInPlace(const MappedFile& file, const TckHeaderInfo& info) {
  if (info.datatype.bytes != 4 || info.datatype.needsSwap()) return false;
  const uint64_t bytes = file.size() - info.data_offset;
  if (bytes < kTriplet || bytes % kTriplet != 0) return false;
  const uint8_t* last = file.data() + file.size() - kTriplet;
  if (tripletKind(last) != SampleKind::kInf) return false;
  return bytes == kTriplet || tripletKind(last - kTriplet) == SampleKind::kNaN;
}

TckStreamlineScan::TckStreamlineScan(TrackDataStream& data, uint64_t data_begin, uint64_t begin, uint64_t stop)
    : data_(data), stop_(stop), started_(begin == data_begin) {
  // A range after the first reads from the triplet before it: when that is
  // a separator, a streamline starts right at `begin`.
  data_.restart(begin > data_begin ? begin - kTriplet : begin, stop);
}

size_t TckStreamlineScan::findSeparator(bool keep) {
  size_t scanned = 0;  // samples at the front known finite, whole triplets
  while (true) {
    const size_t available = data_.available() / 4;
    const size_t hit = scanned + findNonFinite(data_.data() + 4 * scanned, available - scanned, kFloat32);
    if (hit < available && hit - hit % 3 + 3 <= available) return hit;
    // Not in the buffer, or its triplet is cut by the buffer's end.
    const size_t whole = (hit < available ? hit : available) / 3 * 3;
    if (data_.position() + data_.available() >= data_.end()) return kNone;
    if (data_.available() >= data_.capacity() / 2) {
      // The streamline fills the buffer: move what there is of it aside.
      const float* front = reinterpret_cast<const float*>(data_.data());
      if (keep) long_.insert(long_.end(), front, front + whole);
      data_.consume(4 * whole);
      scanned = 0;
    } else {
      scanned = whole;
    }
    data_.fill(data_.available() + kTriplet);  // moves the rest to the front and reads ahead
  }
}

TckStreamlineScan::Step TckStreamlineScan::skipToStart() {
  data_.fill(kTriplet);
  const size_t hit = findSeparator(/*keep=*/false);  // what it passes belongs to the range before
  if (hit == kNone || hit % 3 != 0) return Step::Damaged;
  const uint8_t* triplet = data_.data() + 4 * hit;
  const auto kind = tripletKind(triplet);
  const uint64_t after = data_.position() + 4 * hit + kTriplet;
  data_.consume(4 * hit + kTriplet);
  if (kind == SampleKind::kNaN) return Step::Streamline;
  // The range lies inside the last streamline, up to the terminator.
  return kind == SampleKind::kInf && after == data_.end() ? Step::Done : Step::Damaged;
}

TckStreamlineScan::Step TckStreamlineScan::next() {
  if (done_) return Step::Done;
  if (!started_) {
    started_ = true;
    const Step s = skipToStart();
    if (s != Step::Streamline) {
      done_ = true;
      return s;
    }
  }
  if (data_.position() >= stop_) {
    done_ = true;
    return Step::Done;
  }
  long_.clear();
  data_.fill(kTriplet);
  const size_t hit = findSeparator(/*keep=*/true);
  if (hit == kNone || hit % 3 != 0) {
    done_ = true;
    return Step::Damaged;
  }
  const uint8_t* triplet = data_.data() + 4 * hit;
  const auto kind = tripletKind(triplet);
  if (kind == SampleKind::kNaN) {
    const float* front = reinterpret_cast<const float*>(data_.data());
    if (long_.empty()) {
      points_ = front;
    } else {
      long_.insert(long_.end(), front, front + hit);
      points_ = long_.data();
    }
    count_ = (long_.empty() ? hit : long_.size()) / 3;
    data_.consume(4 * hit + kTriplet);  // the bytes stay in the buffer until the next fill
    return Step::Streamline;
  }
  done_ = true;
  const bool terminator = kind == SampleKind::kInf && hit == 0 && long_.empty() &&
                          data_.position() + kTriplet == data_.end();
  return terminator ? Step::Done : Step::Damaged;
}

}  // namespace fibscope
