// VideoWriter: MP4 files decoded back with FFmpeg's libraries; the sRGB table of ToRgba8.
#include "partsim/render/video.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "partsim/core/error.h"
#include "partsim/render/image_io.h"

extern "C" {
#include <libavcodec/avcodec.h>
#include <libavformat/avformat.h>
#include <libswscale/swscale.h>
}

namespace partsim {
namespace {

namespace fs = std::filesystem;

fs::path TempDir(const std::string& name) {
  fs::path d =
      fs::temp_directory_path() / ("partsim_video_test_" + std::to_string(getpid()) + "_" + name);
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

// What a player sees: every frame of the first video stream as packed RGB.
struct Decoded {
  int width = 0, height = 0;
  double fps = 0;
  std::string codec;
  std::vector<std::vector<uint8_t>> frames;
};

Decoded Decode(const std::string& path) {
  Decoded out;
  AVFormatContext* fmt = nullptr;
  if (avformat_open_input(&fmt, path.c_str(), nullptr, nullptr) < 0) return out;
  avformat_find_stream_info(fmt, nullptr);
  int si = av_find_best_stream(fmt, AVMEDIA_TYPE_VIDEO, -1, -1, nullptr, 0);
  if (si < 0) {
    avformat_close_input(&fmt);
    return out;
  }
  AVStream* st = fmt->streams[si];
  const AVCodec* codec = avcodec_find_decoder(st->codecpar->codec_id);
  AVCodecContext* dec = avcodec_alloc_context3(codec);
  avcodec_parameters_to_context(dec, st->codecpar);
  avcodec_open2(dec, codec, nullptr);
  out.width = dec->width;
  out.height = dec->height;
  out.fps = av_q2d(st->avg_frame_rate);
  out.codec = codec->name;
  AVPacket* pkt = av_packet_alloc();
  AVFrame* frame = av_frame_alloc();
  SwsContext* sws = nullptr;
  auto drain = [&]() {
    while (avcodec_receive_frame(dec, frame) == 0) {
      sws = sws_getCachedContext(
          sws, frame->width, frame->height, static_cast<AVPixelFormat>(frame->format), frame->width,
          frame->height, AV_PIX_FMT_RGB24, SWS_BILINEAR, nullptr, nullptr, nullptr);
      std::vector<uint8_t> rgb(3 * frame->width * frame->height);
      uint8_t* dst[1] = {rgb.data()};
      int stride[1] = {3 * frame->width};
      sws_scale(sws, frame->data, frame->linesize, 0, frame->height, dst, stride);
      out.frames.push_back(std::move(rgb));
    }
  };
  while (av_read_frame(fmt, pkt) >= 0) {
    if (pkt->stream_index == si) {
      avcodec_send_packet(dec, pkt);
      drain();
    }
    av_packet_unref(pkt);
  }
  avcodec_send_packet(dec, nullptr);
  drain();
  sws_freeContext(sws);
  av_frame_free(&frame);
  av_packet_free(&pkt);
  avcodec_free_context(&dec);
  avformat_close_input(&fmt);
  return out;
}

// Frame k: the left half red, the right half a grey that brightens with k.
std::vector<uint8_t> TestFrame(int w, int h, int k, int channels) {
  std::vector<uint8_t> px(static_cast<size_t>(w) * h * channels);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      uint8_t* p = &px[(static_cast<size_t>(y) * w + x) * channels];
      if (x < w / 2) {
        p[0] = 220, p[1] = 30, p[2] = 30;
      } else {
        p[0] = p[1] = p[2] = static_cast<uint8_t>(40 + 20 * k);
      }
      if (channels == 4) p[3] = 255;
    }
  return px;
}

TEST(VideoWriterTest, WritesAnH264Mp4ThatDecodesToTheFrames) {
  fs::path dir = TempDir("h264");
  const std::string path = (dir / "v.mp4").string();
  {
    VideoOptions o;
    o.fps = 20;
    VideoWriter v(path, 96, 64, o);
    EXPECT_EQ(v.Codec(), "libx264");
    for (int k = 0; k < 10; ++k)
      v.AddFrame(TestFrame(96, 64, k, k % 2 ? 3 : 4).data(), k % 2 ? 3 : 4);
    EXPECT_EQ(v.FrameCount(), 10);
    // nothing at the final path before Close: the file is written beside it
    EXPECT_FALSE(fs::exists(path));
    v.Close();
    EXPECT_TRUE(fs::exists(path));
    EXPECT_FALSE(fs::exists(path + ".partial"));
  }
  Decoded d = Decode(path);
  EXPECT_EQ(d.codec, "h264");
  EXPECT_EQ(d.width, 96);
  EXPECT_EQ(d.height, 64);
  EXPECT_NEAR(d.fps, 20.0, 1e-6);
  ASSERT_EQ(d.frames.size(), 10u);
  for (int k = 0; k < 10; ++k) {
    const uint8_t* red = &d.frames[k][3 * (32 * 96 + 20)];
    const uint8_t* grey = &d.frames[k][3 * (32 * 96 + 70)];
    EXPECT_NEAR(red[0], 220, 12) << "frame " << k;
    EXPECT_NEAR(red[1], 30, 12) << "frame " << k;
    EXPECT_NEAR(grey[1], 40 + 20 * k, 6) << "frame " << k;  // frames stay in order
  }
}

TEST(VideoWriterTest, CompositesTransparencyOverTheBackgroundAndCropsOddSizes) {
  fs::path dir = TempDir("alpha");
  const std::string path = (dir / "a.mp4").string();
  VideoOptions o;
  o.background = Eigen::Vector3f(1, 1, 1);  // white
  {
    VideoWriter v(path, 33, 21, o);
    std::vector<uint8_t> clear(33 * 21 * 4, 0);  // fully transparent black
    v.AddFrame(clear.data(), 4);
  }  // the destructor finishes the file
  Decoded d = Decode(path);
  EXPECT_EQ(d.width, 32);
  EXPECT_EQ(d.height, 20);
  ASSERT_EQ(d.frames.size(), 1u);
  EXPECT_GT(d.frames[0][3 * (10 * 32 + 16)], 240);
}

TEST(VideoWriterTest, WritesPictures) {
  fs::path dir = TempDir("picture");
  Picture p;
  p.width = 16;
  p.height = 16;
  p.outputs = kColor;
  p.color.assign(16 * 16 * 4, 1.0f);
  VideoWriter v((dir / "p.mp4").string(), 16, 16);
  v.AddFrame(p);
  Picture wrong = p;
  wrong.width = 8;
  wrong.color.resize(8 * 16 * 4);
  try {
    v.AddFrame(wrong);
    FAIL() << "a picture of another size was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("8 x 16"), std::string::npos) << e.what();
  }
  Picture depth_only = p;
  depth_only.outputs = kPosition;
  depth_only.color.clear();
  EXPECT_THROW(v.AddFrame(depth_only), Error);
  v.Close();
  EXPECT_EQ(Decode((dir / "p.mp4").string()).frames.size(), 1u);
}

TEST(VideoWriterTest, BadArgumentsNameWhatIsWrong) {
  fs::path dir = TempDir("bad");
  auto message = [](auto&& f) {
    try {
      f();
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string("(no error)");
  };
  const std::string p = (dir / "x.mp4").string();
  EXPECT_NE(message([&] { VideoWriter v(p, 0, 10); }).find("frame size"), std::string::npos);
  VideoOptions fps;
  fps.fps = std::nan("");
  EXPECT_NE(message([&] { VideoWriter v(p, 10, 10, fps); }).find("fps"), std::string::npos);
  VideoOptions q;
  q.quality = 60;
  EXPECT_NE(message([&] { VideoWriter v(p, 10, 10, q); }).find("quality"), std::string::npos);
  // a folder that does not exist: the error names the file, and nothing is left behind
  const std::string missing = (dir / "no" / "such" / "x.mp4").string();
  std::string m = message([&] { VideoWriter v(missing, 10, 10); });
  EXPECT_NE(m.find(missing), std::string::npos) << m;
  EXPECT_FALSE(fs::exists(dir / "no"));
  VideoWriter v(p, 10, 10);
  EXPECT_NE(message([&] { v.AddFrame(nullptr, 3); }).find("null"), std::string::npos);
  std::vector<uint8_t> px(10 * 10 * 2);
  EXPECT_NE(message([&] { v.AddFrame(px.data(), 2); }).find("channels"), std::string::npos);
  v.Close();
  EXPECT_NE(message([&] { v.AddFrame(px.data(), 3); }).find("after Close"), std::string::npos);
}

// The table gives the bytes of the sRGB formula (255 thresholds, checked on a dense grid and at
// both sides of every threshold), and NaN, negatives and values above 1 clamp.
TEST(ToRgba8Test, TableMatchesTheSrgbFormula) {
  auto formula = [](float x) {
    x = std::min(std::max(x, 0.0f), 1.0f);
    float s = x <= 0.0031308f ? 12.92f * x : 1.055f * std::pow(x, 1.0f / 2.4f) - 0.055f;
    return static_cast<int>(std::lround(std::min(std::max(s, 0.0f), 1.0f) * 255.0f));
  };
  std::vector<float> in;
  for (int i = 0; i <= 200000; ++i) in.insert(in.end(), {i / 200000.0f, 0.0f, 0.0f, 1.0f});
  std::vector<uint8_t> out = ToRgba8(in);
  int differ = 0;
  for (size_t i = 0; i < in.size(); i += 4) {
    const int want = formula(in[i]);
    EXPECT_LE(std::abs(out[i] - want), 1) << in[i];
    differ += out[i] != want;
  }
  // only values within float rounding of a threshold may land on the other side
  EXPECT_LE(differ, 4);
  std::vector<uint8_t> edge = ToRgba8({std::nanf(""), -1.0f, 7.0f, 0.5f});
  EXPECT_EQ(edge[0], 0);
  EXPECT_EQ(edge[1], 0);
  EXPECT_EQ(edge[2], 255);
  EXPECT_EQ(edge[3], 128);
}

}  // namespace
}  // namespace partsim
