#pragma once
// One rawlog record read into memory with every length and count it holds checked first.
// MRPT's deserialisers size strings, vectors and deques from the record's own length fields
// before reading them (a corrupt record asked for 3.6-4.3 GB), so RawlogReader never lets MRPT
// read the file: readRawlogRecord() walks the MRPT 2.5 layout of the classes RawlogRecorder
// writes, pulling bytes from the file only as the walk consumes them and refusing any length
// that would take the record past `max_bytes`; MRPT then deserialises the record from those
// bytes alone, so nothing it sizes can exceed the record. Private to hw/drivers.
#include <mrpt/io/CStream.h>
#include <mrpt/obs/CObservation.h>

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace sketchnav::drivers {

/// The largest record the reader takes: far above any record RawlogRecorder writes (a 2-D
/// scan of a million beams is 9 MB; images are files beside the log).
constexpr std::size_t kMaxRawlogRecordBytes = std::size_t{64} << 20;

struct RawlogRecordRead {
  enum class Status {
    Ok,          ///< `bytes` holds one whole record
    End,         ///< the file ended between records
    Incomplete,  ///< the file ended inside the record (a cut tail)
    Corrupt,     ///< a field is impossible or a version is not one we write
    Foreign,     ///< a top-level class run --record does not write (e.g. an MRPT dataset's
                 ///< CSensoryFrame); nothing past its header was read
  };
  Status status = Status::End;
  std::string field;  ///< Incomplete / Corrupt: the field and what is wrong with it
};

/// Reads the next record (one top-level MRPT object: CObservation2DRangeScan v6-7,
/// CObservationRange v0-3, CObservationOdometry v0-2, CObservationImage v4 with an external
/// or raw image) from `in` into `bytes`. `bytes` never grows past `max_bytes` plus 64 KiB.
RawlogRecordRead readRawlogRecord(mrpt::io::CStream& in, std::vector<std::uint8_t>& bytes,
                                  std::size_t max_bytes = kMaxRawlogRecordBytes);

/// The observation in a record readRawlogRecord() returned Ok for, deserialised by MRPT from
/// `bytes` alone (so nothing it sizes can exceed the record). Null, with `bad` naming what is
/// wrong, when MRPT fails or consumes another length than the walk did.
mrpt::obs::CObservation::Ptr decodeRawlogRecord(const std::vector<std::uint8_t>& bytes,
                                                std::string& bad);

}  // namespace sketchnav::drivers
