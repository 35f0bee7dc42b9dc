// gvins-rtcm ntrip URL -o FILE [--duration S] [--frames N] [--version 1|2] [--timeout S] [--gga NMEA]
// Records an NTRIP stream byte for byte, decoding it on the way for progress and a summary.
#include <chrono>
#include <cstdio>
#include <cstring>
#include <iomanip>
#include <iostream>

#include "commands.hpp"
#include "gvins/base/command_line.hpp"
#include "gvins/rtcm/framer.hpp"
#include "gvins/rtcm/ntrip_client.hpp"
#include "stream_summary.hpp"

namespace gvins::rtcm_app {

int runNtrip(int argc, char** argv) {
  std::string url, outPath;
  double duration = 0.0;
  long long maxFrames = 0;
  rtcm::NtripOptions nopt;
  CommandLine cl("gvins-rtcm ntrip", kUsage, argc, argv, 2);
  while (cl.next()) {
    if (cl.is("-o")) outPath = cl.value();
    else if (cl.is("--duration")) duration = cl.number(0.0, 1e8, "s");
    else if (cl.is("--frames")) maxFrames = static_cast<long long>(cl.number(0.0, 1e15));
    else if (cl.is("--version")) nopt.version = static_cast<int>(cl.number(1.0, 2.0));
    else if (cl.is("--timeout")) nopt.readTimeout = nopt.connectTimeout = cl.number(0.1, 3600.0, "s");
    else if (cl.is("--gga")) nopt.gga = cl.value();
    else if (url.empty()) url = cl.operand();
    else {
      cl.operand();  // an unknown option is reported as such
      cl.error("more than one URL");
    }
  }
  if (url.empty()) cl.error("no URL (ntrip://user:pass@host:port/MOUNT)");
  if (outPath.empty()) cl.error("no output file (-o FILE)");
  if (nopt.version != 1 && nopt.version != 2) cl.error("--version must be 1 or 2");

  rtcm::NtripClient client(rtcm::NtripUrl::parse(url), nopt);
  std::cerr << "connecting to " << client.url().display() << " (NTRIP " << nopt.version << ".0)\n";
  client.connect();
  std::cerr << "caster answered '" << client.statusLine() << "'" << (client.chunked() ? ", chunked" : "") << "\n";

  std::FILE* out = outPath == "-" ? stdout : std::fopen(outPath.c_str(), "wb");
  if (!out) throw std::runtime_error("cannot create '" + outPath + "': " + std::strerror(errno));
  rtcm::DecoderOptions dopt;
  dopt.streamName = client.url().display();
  rtcm::Decoder dec(dopt);
  rtcm::Framer counter;  // frame boundaries for --frames
  long long frames = 0;
  std::int64_t written = 0;
  const auto t0 = std::chrono::steady_clock::now();
  auto elapsed = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(); };
  double lastReport = -1.0;
  bool done = false;
  std::vector<std::uint8_t> buf;
  while (!done) {
    buf.clear();
    const std::size_t n = client.read(buf);
    if (n == 0) {
      std::cerr << "\ncaster ended the stream\n";
      break;
    }
    std::size_t keep = buf.size();
    counter.feed(buf);
    rtcm::Frame f;
    while (counter.next(f)) {
      if (maxFrames > 0 && ++frames >= maxFrames) {
        keep = static_cast<std::size_t>(f.offset + static_cast<std::int64_t>(f.size()) - written);
        done = true;
        break;
      }
    }
    if (maxFrames <= 0) frames = counter.stats().frames;
    std::fwrite(buf.data(), 1, keep, out);
    std::fflush(out);
    dec.feed({buf.data(), keep});
    while (dec.poll()) {
    }
    written += static_cast<std::int64_t>(keep);
    const double t = elapsed();
    if (duration > 0.0 && t >= duration) done = true;
    if (t - lastReport >= 1.0 || done) {
      lastReport = t;
      std::cerr << "\r" << std::fixed << std::setprecision(1) << std::setw(7) << t << " s  " << std::setw(10) << written
                << " bytes  " << std::setw(7) << dec.stats().framing.frames << " frames  "
                << dec.stats().framing.crcFailures << " CRC failures" << std::flush;
    }
  }
  std::cerr << "\n";
  dec.finish();
  while (dec.poll()) {
  }
  if (out != stdout) std::fclose(out);
  printSummary(outPath == "-" ? std::cerr : std::cout, dec, client.url().display());
  return 0;
}

}  // namespace gvins::rtcm_app
