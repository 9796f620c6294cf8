// SPDX-License-Identifier: MIT
// pcap reading and writing: both timestamp precisions, both byte orders, framing variants,
// other traffic skipped and counted, truncated and corrupt files ending with an error after
// every intact record.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "alloc_counter.hpp"
#include "msgraphs/drivers/pcap/pcap_reader.hpp"
#include "msgraphs/drivers/pcap/pcap_writer.hpp"
#include "velodyne_test_packets.hpp"

namespace msgraphs::drivers::pcap {
namespace {

std::string TempPath(const char* name) {
  return (std::filesystem::temp_directory_path() /
          (std::string("msgraphs_") + std::to_string(::getpid()) + "_" + name))
      .string();
}

std::vector<std::uint8_t> Payload(std::size_t n, std::uint8_t seed) {
  std::vector<std::uint8_t> p(n);
  for (std::size_t i = 0; i < n; ++i) p[i] = static_cast<std::uint8_t>(seed + i * 7);
  return p;
}

const Ipv4Endpoint kSensor{0xC0A801C9, 2368};       // 192.168.1.201
const Ipv4Endpoint kBroadcast{0xFFFFFFFF, 2368};

class PcapRoundTrip : public ::testing::TestWithParam<TimestampPrecision> {};

TEST_P(PcapRoundTrip, WrittenUdpRecordsReadBackExactly) {
  const std::string path = TempPath("roundtrip.pcap");
  const auto precision = GetParam();
  const UnixTime t0 = UnixTime::FromNanoseconds(1'700'000'000'123'456'789);
  {
    auto writer = PcapFileWriter::Create(path.c_str(), precision).value();
    for (int i = 0; i < 500; ++i) {
      const auto payload = Payload(i % 2 == 0 ? 1206 : 512, static_cast<std::uint8_t>(i));
      const Ipv4Endpoint to{kBroadcast.address, static_cast<std::uint16_t>(i % 2 == 0 ? 2368 : 8308)};
      ASSERT_TRUE(writer.WriteUdp(t0 + Duration::FromMicroseconds(1327 * i), kSensor, to, payload));
    }
    ASSERT_TRUE(writer.Close());
  }
  auto reader = PcapFileReader::Open(path.c_str()).value();
  EXPECT_EQ(reader.header().precision, precision);
  EXPECT_EQ(reader.header().link_type, 1u);
  PcapRecord record;
  PcapUdpCounters counters;
  int i = 0;
  while (reader.Next(record).value()) {
    auto d = ExtractUdp(reader.header(), record, counters).value();
    const auto expected = Payload(i % 2 == 0 ? 1206 : 512, static_cast<std::uint8_t>(i));
    ASSERT_EQ(std::vector<std::uint8_t>(d.payload.begin(), d.payload.end()), expected) << i;
    EXPECT_EQ(d.source, kSensor);
    EXPECT_EQ(d.destination.port, i % 2 == 0 ? 2368 : 8308);
    const std::int64_t want_ns = (t0 + Duration::FromMicroseconds(1327 * i)).nanoseconds_since_epoch();
    const std::int64_t got_ns = record.header.timestamp.nanoseconds_since_epoch();
    if (precision == TimestampPrecision::kNanoseconds) {
      EXPECT_EQ(got_ns, want_ns);
    } else {
      EXPECT_EQ(got_ns, want_ns / 1000 * 1000);
    }
    ++i;
  }
  EXPECT_EQ(i, 500);
  EXPECT_EQ(counters.udp_datagrams, 500u);
  std::remove(path.c_str());
}

INSTANTIATE_TEST_SUITE_P(Precisions, PcapRoundTrip,
                         ::testing::Values(TimestampPrecision::kMicroseconds, TimestampPrecision::kNanoseconds));

// Builds a file in memory: header plus records of raw frames.
struct MemoryPcap {
  std::vector<std::uint8_t> bytes;
  explicit MemoryPcap(std::uint32_t link_type = 1, bool big_endian = false) {
    bytes.resize(kGlobalHeaderBytes);
    WriteGlobalHeader(std::span<std::uint8_t, kGlobalHeaderBytes>(bytes.data(), kGlobalHeaderBytes),
                      TimestampPrecision::kMicroseconds, 65535, static_cast<LinkType>(link_type));
    if (big_endian) SwapWords(0, 6);
  }
  void SwapWords(std::size_t offset, int words) {  // 4-byte words, and 2-byte version fields
    for (int w = 0; w < words; ++w) {
      std::uint8_t* p = bytes.data() + offset + 4 * static_cast<std::size_t>(w);
      if (offset == 0 && w == 1) {  // version major/minor are two u16
        std::swap(p[0], p[1]);
        std::swap(p[2], p[3]);
      } else {
        std::swap(p[0], p[3]);
        std::swap(p[1], p[2]);
      }
    }
  }
  void Add(std::span<const std::uint8_t> frame, std::uint32_t seconds = 100, bool big_endian = false) {
    const std::size_t at = bytes.size();
    bytes.resize(at + kRecordHeaderBytes);
    WriteRecordHeader(std::span<std::uint8_t, kRecordHeaderBytes>(bytes.data() + at, kRecordHeaderBytes),
                      UnixTime::FromNanoseconds(static_cast<std::int64_t>(seconds) * 1'000'000'000 + 5000),
                      TimestampPrecision::kMicroseconds, static_cast<std::uint32_t>(frame.size()),
                      static_cast<std::uint32_t>(frame.size()));
    if (big_endian) SwapWords(at, 4);
    bytes.insert(bytes.end(), frame.begin(), frame.end());
  }
};

std::vector<std::uint8_t> UdpFrame(std::size_t payload_bytes, std::uint16_t port = 2368) {
  std::vector<std::uint8_t> frame(payload_bytes + kEthernetIpv4UdpHeaderBytes);
  const auto payload = Payload(payload_bytes, 3);
  const std::size_t n = BuildUdpFrame(kSensor, {0x0A000001, port}, payload, frame).value();
  frame.resize(n);
  return frame;
}

// pcap_writer.hpp: "Buffered in one fixed buffer allocated at Create; writes never allocate".
// The writer is created and the payloads made first; 500 records (about 600 kB, so the buffer
// is flushed to the file on the way) are written inside the scope.
TEST(PcapWriter, WritesNeverAllocate) {
  const std::string path = TempPath("writes.pcap");
  const UnixTime t0 = UnixTime::FromNanoseconds(1'700'000'000'000'000'000);
  const std::vector<std::uint8_t> scan = Payload(1206, 1), position = Payload(512, 2);
  const std::vector<std::uint8_t> frame = UdpFrame(100);
  {
    auto writer = PcapFileWriter::Create(path.c_str(), TimestampPrecision::kNanoseconds).value();
    int failures = 0;
    std::uint64_t allocations = 0;
    {
      test::AllocationScope scope;
      for (int i = 0; i < 500; ++i) {
        const UnixTime t = t0 + Duration::FromMicroseconds(1327 * i);
        const Status s = i % 10 == 9 ? writer.WriteFrame(t, frame)
                         : i % 2 == 0 ? writer.WriteUdp(t, kSensor, kBroadcast, scan)
                                      : writer.WriteUdp(t, kSensor, kBroadcast, position);
        if (!s) ++failures;
      }
      allocations = scope.allocations();
    }
    EXPECT_EQ(allocations, 0u);
    EXPECT_EQ(failures, 0);
    EXPECT_EQ(writer.records(), 500u);
    ASSERT_TRUE(writer.Close());
  }
  auto reader = PcapFileReader::Open(path.c_str()).value();
  PcapRecord record;
  int records = 0;
  while (reader.Next(record).value()) ++records;
  EXPECT_EQ(records, 500);
  std::remove(path.c_str());
}

// pcap_reader.hpp: "allocation-free per record", for both readers. The file is written, the
// readers opened (the file reader's buffer is allocated at Open) and the expected payload sum
// computed first; every record is read and parsed to its UDP payload inside the scope.
TEST(PcapReader, ReadingRecordsAllocatesNothing) {
  const std::string path = TempPath("reads.pcap");
  const UnixTime t0 = UnixTime::FromNanoseconds(1'700'000'000'000'000'000);
  std::uint64_t expected_sum = 0;
  {
    auto writer = PcapFileWriter::Create(path.c_str(), TimestampPrecision::kMicroseconds).value();
    for (int i = 0; i < 500; ++i) {
      const auto payload = Payload(i % 2 == 0 ? 1206 : 512, static_cast<std::uint8_t>(i));
      for (const std::uint8_t b : payload) expected_sum += b;
      ASSERT_TRUE(writer.WriteUdp(t0 + Duration::FromMicroseconds(1327 * i), kSensor, kBroadcast, payload));
    }
    ASSERT_TRUE(writer.Close());
  }
  std::vector<std::uint8_t> bytes(static_cast<std::size_t>(std::filesystem::file_size(path)));
  ASSERT_GT(bytes.size(), kGlobalHeaderBytes);
  FILE* f = std::fopen(path.c_str(), "rb");
  ASSERT_NE(f, nullptr);
  const std::size_t got = std::fread(bytes.data(), 1, bytes.size(), f);
  std::fclose(f);
  ASSERT_EQ(got, bytes.size());
  auto file_reader = PcapFileReader::Open(path.c_str()).value();
  auto buffer_reader = PcapBufferReader::Open(bytes).value();
  PcapRecord record;
  PcapUdpCounters file_counters, buffer_counters;
  std::uint64_t file_sum = 0, buffer_sum = 0;
  bool file_clean_end = true, buffer_clean_end = true;

  // Reads every record and sums its UDP payload; false when the reader stopped on an error.
  auto drain = [&record](auto& reader, PcapUdpCounters& counters, std::uint64_t& sum) {
    for (;;) {
      const Expected<bool> next = reader.Next(record);
      if (!next || !*next) return next.has_value();
      if (auto d = ExtractUdp(reader.header(), record, counters)) {
        for (const std::uint8_t b : d->payload) sum += b;
      }
    }
  };
  test::AllocationScope scope;
  file_clean_end = drain(file_reader, file_counters, file_sum);
  buffer_clean_end = drain(buffer_reader, buffer_counters, buffer_sum);
  const std::uint64_t allocations = scope.allocations();

  EXPECT_EQ(allocations, 0u);
  EXPECT_TRUE(file_clean_end);
  EXPECT_TRUE(buffer_clean_end);
  EXPECT_EQ(file_reader.records(), 500u);
  EXPECT_EQ(buffer_reader.records(), 500u);
  EXPECT_EQ(file_counters.udp_datagrams, 500u);
  EXPECT_EQ(buffer_counters.udp_datagrams, 500u);
  EXPECT_EQ(file_sum, expected_sum);
  EXPECT_EQ(buffer_sum, expected_sum);
  std::remove(path.c_str());
}

TEST(PcapReader, ReadsBigEndianFiles) {
  MemoryPcap file(1, true);
  const auto frame = UdpFrame(1206);
  file.Add(frame, 100, true);
  file.Add(frame, 101, true);
  auto reader = PcapBufferReader::Open(file.bytes).value();
  EXPECT_TRUE(reader.header().swapped);
  PcapRecord r;
  ASSERT_TRUE(reader.Next(r).value());
  EXPECT_EQ(r.header.captured_bytes, frame.size());
  EXPECT_EQ(r.header.timestamp.nanoseconds_since_epoch(), 100'000'005'000);
  ASSERT_TRUE(reader.Next(r).value());
  EXPECT_FALSE(reader.Next(r).value());
}

TEST(PcapReader, TruncatedFileKeepsEveryIntactRecordThenFails) {
  MemoryPcap file;
  for (int i = 0; i < 10; ++i) file.Add(UdpFrame(1206));
  for (std::size_t cut : {std::size_t{5}, std::size_t{600}, std::size_t{1248 + 10}}) {
    std::vector<std::uint8_t> bytes(file.bytes.begin(), file.bytes.end() - static_cast<std::ptrdiff_t>(cut));
    auto reader = PcapBufferReader::Open(bytes).value();
    PcapRecord r;
    int good = 0;
    Expected<bool> next = true;
    while ((next = reader.Next(r)) && *next) ++good;
    ASSERT_FALSE(next.has_value()) << cut;
    EXPECT_EQ(next.error().code, Errc::kMalformed);
    EXPECT_NE(std::string(next.error().detail).find("truncated"), std::string::npos);
    EXPECT_EQ(good, cut > 1264 ? 8 : 9) << cut;
    EXPECT_FALSE(reader.Next(r).has_value()) << "the error is sticky";
  }
}

TEST(PcapReader, TruncatedFileOnDiskBehavesTheSame) {
  MemoryPcap file;
  for (int i = 0; i < 10; ++i) file.Add(UdpFrame(1206));
  const std::string path = TempPath("truncated.pcap");
  FILE* f = std::fopen(path.c_str(), "wb");
  std::fwrite(file.bytes.data(), 1, file.bytes.size() - 100, f);
  std::fclose(f);
  auto reader = PcapFileReader::Open(path.c_str()).value();
  PcapRecord r;
  int good = 0;
  Expected<bool> next = true;
  while ((next = reader.Next(r)) && *next) ++good;
  EXPECT_EQ(good, 9);
  ASSERT_FALSE(next.has_value());
  EXPECT_EQ(next.error().code, Errc::kMalformed);
  std::remove(path.c_str());
}

TEST(PcapReader, CorruptRecordLengthIsAnErrorNotAnAllocation) {
  MemoryPcap file;
  file.Add(UdpFrame(1206));
  file.Add(UdpFrame(1206));
  // Second record header: captured length 0x7FFFFFFF.
  const std::size_t second = kGlobalHeaderBytes + kRecordHeaderBytes + 1248;
  file.bytes[second + 8] = 0xFF;
  file.bytes[second + 9] = 0xFF;
  file.bytes[second + 10] = 0xFF;
  file.bytes[second + 11] = 0x7F;
  auto reader = PcapBufferReader::Open(file.bytes).value();
  PcapRecord r;
  ASSERT_TRUE(reader.Next(r).value());
  auto next = reader.Next(r);
  ASSERT_FALSE(next.has_value());
  EXPECT_NE(std::string(next.error().detail).find("262144"), std::string::npos);
}

TEST(PcapReader, RejectsNonPcapAndPcapng) {
  std::vector<std::uint8_t> junk(64, 0x42);
  EXPECT_EQ(PcapBufferReader::Open(junk).error().code, Errc::kMalformed);
  std::vector<std::uint8_t> pcapng = {0x0A, 0x0D, 0x0D, 0x0A};
  pcapng.resize(64);
  EXPECT_EQ(PcapBufferReader::Open(pcapng).error().code, Errc::kUnsupported);
  EXPECT_EQ(PcapBufferReader::Open(std::span<const std::uint8_t>(junk).first(10)).error().code, Errc::kMalformed);
  EXPECT_EQ(PcapFileReader::Open("/nonexistent/file.pcap").error().code, Errc::kIo);
}

TEST(UdpFrame, OtherTrafficIsSkippedAndCounted) {
  MemoryPcap file;
  file.Add(UdpFrame(1206));
  std::vector<std::uint8_t> arp(42, 0);
  arp[12] = 0x08;
  arp[13] = 0x06;
  file.Add(arp);
  auto tcp = UdpFrame(100);
  tcp[14 + 9] = 6;
  file.Add(tcp);
  auto fragment = UdpFrame(100);
  fragment[14 + 6] = 0x20;  // more fragments
  file.Add(fragment);
  auto ipv6 = UdpFrame(100);
  ipv6[12] = 0x86;
  ipv6[13] = 0xDD;
  file.Add(ipv6);
  auto bad_ihl = UdpFrame(100);
  bad_ihl[14] = 0x42;
  file.Add(bad_ihl);
  auto bad_udp_length = UdpFrame(100);
  bad_udp_length[14 + 20 + 4] = 0xFF;
  file.Add(bad_udp_length);
  auto cut = UdpFrame(1206);
  cut.resize(600);  // snaplen cut the datagram
  file.Add(cut);

  auto reader = PcapBufferReader::Open(file.bytes).value();
  PcapRecord r;
  PcapUdpCounters counters;
  int udp = 0;
  while (reader.Next(r).value()) {
    if (auto d = ExtractUdp(reader.header(), r, counters); d && !d->payload_truncated) ++udp;
  }
  EXPECT_EQ(udp, 1);
  EXPECT_EQ(counters.records, 8u);
  EXPECT_EQ(counters.other_traffic, 4u);
  EXPECT_EQ(counters.malformed_frames, 2u);
  EXPECT_EQ(counters.truncated_payloads, 1u);
}

TEST(UdpFrame, VlanLinuxSllAndRawIpFramings) {
  const auto plain = UdpFrame(1206);
  std::vector<std::uint8_t> vlan(plain.begin(), plain.begin() + 12);
  vlan.insert(vlan.end(), {0x81, 0x00, 0x00, 0x05});
  vlan.insert(vlan.end(), plain.begin() + 12, plain.end());
  auto d = ParseUdpFrame(1, vlan);
  ASSERT_TRUE(d.has_value());
  EXPECT_EQ(d->payload.size(), 1206u);

  std::vector<std::uint8_t> sll(16, 0);
  sll[14] = 0x08;
  sll.insert(sll.end(), plain.begin() + 14, plain.end());
  d = ParseUdpFrame(113, sll);
  ASSERT_TRUE(d.has_value());
  EXPECT_EQ(d->destination.port, 2368);

  std::vector<std::uint8_t> raw(plain.begin() + 14, plain.end());
  d = ParseUdpFrame(101, raw);
  ASSERT_TRUE(d.has_value());
  EXPECT_EQ(d->source, kSensor);
  EXPECT_EQ(ParseUdpFrame(147, raw).error().code, Errc::kUnsupported);
}

TEST(UdpFrame, BuiltIpv4HeaderChecksumVerifies) {
  const auto frame = UdpFrame(512);
  std::uint32_t sum = 0;
  for (std::size_t i = 14; i < 34; i += 2) sum += static_cast<std::uint32_t>((frame[i] << 8) | frame[i + 1]);
  while (sum >> 16) sum = (sum & 0xFFFF) + (sum >> 16);
  EXPECT_EQ(sum, 0xFFFFu);
}

TEST(Ipv4Address, ParseAndFormat) {
  EXPECT_EQ(ParseIpv4Address("192.168.1.201").value(), 0xC0A801C9u);
  EXPECT_EQ(std::string(FormatIpv4Address(0xC0A801C9u).data()), "192.168.1.201");
  EXPECT_EQ(std::string(FormatIpv4Address(0).data()), "0.0.0.0");
  for (const char* bad : {"", "1.2.3", "1.2.3.4.5", "256.1.1.1", "1.2.3.x", "1..2.3", "01234.1.1.1"}) {
    EXPECT_FALSE(ParseIpv4Address(bad).has_value()) << bad;
  }
}

}  // namespace
}  // namespace msgraphs::drivers::pcap
