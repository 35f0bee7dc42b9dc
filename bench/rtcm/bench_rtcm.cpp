// RTCM 3 throughput: framing alone, full decoding (observations, ephemerides) of the bundled
// logs, and MSM7 encoding. Bytes/s are the input (decoding) or output (encoding) stream bytes.
#include <benchmark/benchmark.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <vector>

#include "gvins/rtcm/decoder.hpp"
#include "gvins/rtcm/encoder.hpp"
#include "gvins/rtcm/framer.hpp"

namespace {

using namespace gvins;

std::vector<std::uint8_t> load(const char* name) {
  std::ifstream in(std::filesystem::path(GVINS_TEST_DATA) / "rtcm" / name, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

GpsTime refFor(const char* name) {
  const std::string n = name;
  CalendarTime c;
  c.hour = 12;
  if (n.find("GMSD") != std::string::npos) c = {2012, 10, 13, 12, 0, 0.0};
  else if (n.find("testglo") != std::string::npos) c = {2009, 12, 18, 12, 0, 0.0};
  else c = {2023, 8, 17, 12, 0, 0.0};
  return GpsTime::fromCalendar(c);
}

const char* kFiles[] = {"rtklib_testglo.rtcm3", "rtklib_GMSD7_20121014.rtcm3", "cssrlib_idd2023229c.rtc"};

void BM_Framer(benchmark::State& state) {
  const auto data = load(kFiles[state.range(0)]);
  std::int64_t frames = 0;
  for (auto _ : state) {
    rtcm::Framer f;
    rtcm::Frame fr;
    for (std::size_t i = 0; i < data.size(); i += 65536) {
      f.feed({data.data() + i, std::min<std::size_t>(65536, data.size() - i)});
      while (f.next(fr)) ++frames;
    }
    benchmark::DoNotOptimize(frames);
  }
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations()) * static_cast<std::int64_t>(data.size()));
  state.SetLabel(kFiles[state.range(0)]);
}
BENCHMARK(BM_Framer)->DenseRange(0, 2);

void BM_Decode(benchmark::State& state) {
  const char* name = kFiles[state.range(0)];
  const auto data = load(name);
  std::int64_t items = 0;
  for (auto _ : state) {
    rtcm::DecoderOptions opt;
    opt.referenceTime = refFor(name);
    rtcm::Decoder dec(opt);
    for (std::size_t i = 0; i < data.size(); i += 65536) {
      dec.feed({data.data() + i, std::min<std::size_t>(65536, data.size() - i)});
      while (auto d = dec.poll()) ++items;
    }
    dec.finish();
    while (auto d = dec.poll()) ++items;
    benchmark::DoNotOptimize(items);
  }
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations()) * static_cast<std::int64_t>(data.size()));
  state.SetLabel(name);
}
BENCHMARK(BM_Decode)->DenseRange(0, 2);

void BM_EncodeMsm7(benchmark::State& state) {
  const auto data = load("rtklib_GMSD7_20121014.rtcm3");
  rtcm::DecoderOptions opt;
  opt.referenceTime = refFor("GMSD");
  rtcm::Decoder dec(opt);
  dec.feed(data);
  dec.finish();
  std::vector<ObsEpoch> epochs;
  while (auto d = dec.poll()) {
    if (auto* e = std::get_if<ObsEpoch>(&*d)) epochs.push_back(*e);
  }
  std::int64_t bytes = 0;
  for (auto _ : state) {
    rtcm::Encoder enc;
    enc.setGlonassChannels(dec.glonassChannels());
    for (const ObsEpoch& e : epochs) bytes += static_cast<std::int64_t>(enc.msm(e, 7).size());
  }
  state.SetBytesProcessed(bytes);
  state.counters["epochs/s"] = benchmark::Counter(static_cast<double>(epochs.size()) * static_cast<double>(state.iterations()),
                                                  benchmark::Counter::kIsRate);
}
BENCHMARK(BM_EncodeMsm7);

}  // namespace

BENCHMARK_MAIN();
