// MP4 writer on FFmpeg's libraries (libavformat, libavcodec, libswscale from Debian).
#include "partsim/render/video.h"

#include <cmath>
#include <cstdio>
#include <mutex>
#include <optional>
#include <vector>

#include "core/atomic_file.h"
#include "partsim/core/check.h"
#include "partsim/core/error.h"
#include "partsim/render/image_io.h"

extern "C" {
#include <libavcodec/avcodec.h>
#include <libavformat/avformat.h>
#include <libavutil/error.h>
#include <libavutil/opt.h>
#include <libswscale/swscale.h>
}

namespace partsim {
namespace {

std::string AvError(int code) {
  char buf[AV_ERROR_MAX_STRING_SIZE] = {0};
  av_strerror(code, buf, sizeof(buf));
  return buf;
}

// sRGB encoding of one linear value in [0, 1] (the background colour)
uint8_t ToSrgb8(float linear) {
  std::vector<uint8_t> v = ToRgba8({linear, linear, linear, 1.0f});
  return v[0];
}

}  // namespace

struct VideoWriter::Impl {
  std::string path, partial;  // the video, and the name it is written under until Close
  // renames `partial` onto `path` at Close; removes it when the video is not finished
  std::optional<internal::StagedPath> staged;
  int width = 0, height = 0;  // of the frames given
  int enc_width = 0, enc_height = 0;
  VideoOptions options;
  AVFormatContext* format = nullptr;
  AVCodecContext* encoder = nullptr;
  AVStream* stream = nullptr;
  AVFrame* frame = nullptr;
  AVPacket* packet = nullptr;
  SwsContext* sws = nullptr;
  int frames = 0;
  bool closed = false;
  std::string codec_name;
  std::vector<uint8_t> rgb;  // composited frame

  [[noreturn]] void Fail(const std::string& what, int code = 0) const {
    throw Error("video '" + path + "': " + what + (code < 0 ? ": " + AvError(code) : ""));
  }

  // Sends a frame (nullptr: flush) and writes every packet the encoder has ready.
  void Encode(AVFrame* f) {
    int rc = avcodec_send_frame(encoder, f);
    if (rc < 0) Fail("encoding failed", rc);
    for (;;) {
      rc = avcodec_receive_packet(encoder, packet);
      if (rc == AVERROR(EAGAIN) || rc == AVERROR_EOF) return;
      if (rc < 0) Fail("encoding failed", rc);
      av_packet_rescale_ts(packet, encoder->time_base, stream->time_base);
      packet->stream_index = stream->index;
      rc = av_interleaved_write_frame(format, packet);  // takes the packet's reference
      if (rc < 0) Fail("cannot write to '" + partial + "'", rc);
    }
  }

  void Free() {
    sws_freeContext(sws);
    sws = nullptr;
    av_packet_free(&packet);
    av_frame_free(&frame);
    avcodec_free_context(&encoder);
    if (format) {
      if (format->pb) avio_closep(&format->pb);
      avformat_free_context(format);
      format = nullptr;
    }
  }
};

VideoWriter::VideoWriter(const std::string& path, int width, int height,
                         const VideoOptions& options)
    : impl_(std::make_unique<Impl>()) {
  Impl& s = *impl_;
  s.path = path;
  s.partial = path + ".partial";
  s.width = width;
  s.height = height;
  s.options = options;
  if (path.empty()) throw Error("VideoWriter: the path is empty");
  if (width < 2 || height < 2 || width > 16384 || height > 16384)
    s.Fail("frame size must be in [2, 16384] pixels, got " + std::to_string(width) + " x " +
           std::to_string(height));
  if (!(options.fps > 0 && options.fps <= 1000))
    s.Fail("fps must be in (0, 1000], got " + FormatNumber(options.fps));
  if (options.quality < 0 || options.quality > 51)
    s.Fail("quality must be in [0, 51], got " + std::to_string(options.quality));
  if (!options.background.allFinite()) s.Fail("background colour must be finite");
  s.enc_width = width & ~1;
  s.enc_height = height & ~1;

  static std::once_flag quiet;
  std::call_once(quiet, [] { av_log_set_level(AV_LOG_ERROR); });

  s.staged.emplace(s.path, s.partial);
  try {
    int rc = avformat_alloc_output_context2(&s.format, nullptr, "mp4", s.partial.c_str());
    if (rc < 0 || !s.format) s.Fail("no MP4 muxer", rc);
    const AVCodec* codec = avcodec_find_encoder(AV_CODEC_ID_H264);
    if (!codec) codec = avcodec_find_encoder(AV_CODEC_ID_MPEG4);
    if (!codec) s.Fail("neither an H.264 nor an MPEG-4 encoder is available");
    s.stream = avformat_new_stream(s.format, nullptr);
    s.encoder = avcodec_alloc_context3(codec);
    s.frame = av_frame_alloc();
    s.packet = av_packet_alloc();
    if (!s.stream || !s.encoder || !s.frame || !s.packet) s.Fail("out of memory");
    AVRational rate = av_d2q(options.fps, 100000);
    s.encoder->width = s.enc_width;
    s.encoder->height = s.enc_height;
    s.encoder->framerate = rate;
    s.encoder->time_base = av_inv_q(rate);
    s.encoder->pix_fmt = AV_PIX_FMT_YUV420P;
    s.encoder->gop_size = std::max(1, static_cast<int>(std::lround(2 * options.fps)));
    if (codec->id == AV_CODEC_ID_H264) {
      av_opt_set(s.encoder->priv_data, "preset", "fast", 0);
      av_opt_set_int(s.encoder->priv_data, "crf", options.quality, 0);
    } else {
      // MPEG-4 part 2: a fixed quantiser from the same 0..51 scale
      s.encoder->flags |= AV_CODEC_FLAG_QSCALE;
      s.encoder->global_quality = FF_QP2LAMBDA * std::max(1, 2 + options.quality / 3);
    }
    if (s.format->oformat->flags & AVFMT_GLOBALHEADER)
      s.encoder->flags |= AV_CODEC_FLAG_GLOBAL_HEADER;
    s.codec_name = codec->name;
    rc = avcodec_open2(s.encoder, codec, nullptr);
    if (rc < 0) s.Fail("cannot open the encoder " + s.codec_name, rc);
    rc = avcodec_parameters_from_context(s.stream->codecpar, s.encoder);
    if (rc < 0) s.Fail("cannot set the stream parameters", rc);
    s.stream->time_base = s.encoder->time_base;
    s.stream->avg_frame_rate = rate;

    s.frame->format = s.encoder->pix_fmt;
    s.frame->width = s.enc_width;
    s.frame->height = s.enc_height;
    rc = av_frame_get_buffer(s.frame, 0);
    if (rc < 0) s.Fail("cannot allocate a frame", rc);
    s.sws = sws_getContext(s.enc_width, s.enc_height, AV_PIX_FMT_RGB24, s.enc_width, s.enc_height,
                           AV_PIX_FMT_YUV420P, SWS_BILINEAR, nullptr, nullptr, nullptr);
    if (!s.sws) s.Fail("cannot create the colour converter");

    rc = avio_open(&s.format->pb, s.partial.c_str(), AVIO_FLAG_WRITE);
    if (rc < 0) s.Fail("cannot open '" + s.partial + "' for writing", rc);
    rc = avformat_write_header(s.format, nullptr);
    if (rc < 0) s.Fail("cannot write the MP4 header", rc);
  } catch (...) {
    s.Free();
    s.staged.reset();
    throw;
  }
}

VideoWriter::~VideoWriter() {
  if (!impl_ || impl_->closed) return;
  try {
    Close();
  } catch (const std::exception& e) {
    std::fprintf(stderr, "partsim: %s\n", e.what());
    impl_->Free();
  }
}

void VideoWriter::AddFrame(const uint8_t* pixels, int channels) {
  Impl& s = *impl_;
  if (s.closed) s.Fail("frame added after Close()");
  if (!pixels) s.Fail("frame pixels are null");
  if (channels != 3 && channels != 4)
    s.Fail("frames have 3 or 4 channels, got " + std::to_string(channels));
  const int w = s.enc_width, h = s.enc_height;
  s.rgb.resize(static_cast<size_t>(w) * h * 3);
  const uint8_t bg[3] = {ToSrgb8(s.options.background.x()), ToSrgb8(s.options.background.y()),
                         ToSrgb8(s.options.background.z())};
  for (int y = 0; y < h; ++y) {
    const uint8_t* src = pixels + static_cast<size_t>(y) * s.width * channels;
    uint8_t* dst = s.rgb.data() + static_cast<size_t>(y) * w * 3;
    for (int x = 0; x < w; ++x, src += channels, dst += 3) {
      const int a = channels == 4 ? src[3] : 255;
      for (int c = 0; c < 3; ++c)
        dst[c] = static_cast<uint8_t>((src[c] * a + bg[c] * (255 - a) + 127) / 255);
    }
  }
  int rc = av_frame_make_writable(s.frame);
  if (rc < 0) s.Fail("cannot write a frame", rc);
  const uint8_t* planes[1] = {s.rgb.data()};
  const int strides[1] = {3 * w};
  sws_scale(s.sws, planes, strides, 0, h, s.frame->data, s.frame->linesize);
  s.frame->pts = s.frames;
  s.Encode(s.frame);
  ++s.frames;
}

void VideoWriter::CheckFrameSize(int width, int height) const {
  const Impl& s = *impl_;
  if (width != s.width || height != s.height)
    s.Fail("frame is " + std::to_string(width) + " x " + std::to_string(height) + ", the video " +
           std::to_string(s.width) + " x " + std::to_string(s.height));
}

void VideoWriter::AddFrame(const Picture& picture) {
  Impl& s = *impl_;
  if (!(picture.outputs & kColor) || picture.color.empty())
    s.Fail("the picture has no Color output");
  CheckFrameSize(picture.width, picture.height);
  std::vector<uint8_t> rgba = ToRgba8(picture.color);
  AddFrame(rgba.data(), 4);
}

void VideoWriter::Close() {
  Impl& s = *impl_;
  if (s.closed) return;
  s.closed = true;
  try {
    s.Encode(nullptr);
    int rc = av_write_trailer(s.format);
    if (rc < 0) s.Fail("cannot finish the MP4", rc);
    rc = avio_closep(&s.format->pb);
    if (rc < 0) s.Fail("cannot close '" + s.partial + "'", rc);
    s.Free();
    try {
      s.staged->Commit();
    } catch (const Error& e) {
      s.Fail(e.what());
    }
  } catch (...) {
    s.Free();
    throw;
  }
}

int VideoWriter::FrameCount() const { return impl_->frames; }

std::string VideoWriter::Codec() const { return impl_->codec_name; }

const std::string& VideoWriter::Path() const { return impl_->path; }

}  // namespace partsim
