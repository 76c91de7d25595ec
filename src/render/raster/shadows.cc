// The rasterizer's shadow maps: an orthographic camera around the receivers for a directional
// light, a perspective one over the light's cone for a spot light; 3x3 PCF in the shading reads
// them.
#include "render/raster/shadows.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace partsim::internal::raster {

namespace {

Eigen::Matrix4f ToFloat(const Eigen::Matrix4d& m) { return m.cast<float>(); }

// a right-handed look-at view matrix (world -> eye, eye looks along -z)
Eigen::Matrix4d LookAlong(const Eigen::Vector3d& eye, const Eigen::Vector3d& forward) {
  Eigen::Vector3d f = forward.normalized();
  Eigen::Vector3d up = std::abs(f.z()) < 0.9 ? Eigen::Vector3d::UnitZ() : Eigen::Vector3d::UnitX();
  Eigen::Vector3d x = f.cross(up).normalized();
  Eigen::Vector3d y = x.cross(f);
  Eigen::Matrix4d v = Eigen::Matrix4d::Identity();
  v.block<1, 3>(0, 0) = x.transpose();
  v.block<1, 3>(1, 0) = y.transpose();
  v.block<1, 3>(2, 0) = -f.transpose();
  v(0, 3) = -x.dot(eye);
  v(1, 3) = -y.dot(eye);
  v(2, 3) = f.dot(eye);
  return v;
}

Eigen::Matrix4d Ortho(double l, double r, double b, double t, double n, double f) {
  Eigen::Matrix4d p = Eigen::Matrix4d::Identity();
  p(0, 0) = 2 / (r - l);
  p(1, 1) = 2 / (t - b);
  p(2, 2) = -2 / (f - n);
  p(0, 3) = -(r + l) / (r - l);
  p(1, 3) = -(t + b) / (t - b);
  p(2, 3) = -(f + n) / (f - n);
  return p;
}

Eigen::Matrix4d Perspective(double fovy, double n, double f) {
  double c = 1 / std::tan(fovy / 2);
  Eigen::Matrix4d p = Eigen::Matrix4d::Zero();
  p(0, 0) = c;
  p(1, 1) = c;
  p(2, 2) = -(f + n) / (f - n);
  p(2, 3) = -2 * f * n / (f - n);
  p(3, 2) = -1;
  return p;
}

// A depth array texture of `size` x `size` x `layers` that compares for a shadow sampler.
GLuint MakeDepthArray(int size, int layers) {
  GLuint tex = 0;
  glCreateTextures(GL_TEXTURE_2D_ARRAY, 1, &tex);
  glTextureStorage3D(tex, 1, GL_DEPTH_COMPONENT32F, size, size, layers);
  glTextureParameteri(tex, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  glTextureParameteri(tex, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glTextureParameteri(tex, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTextureParameteri(tex, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  glTextureParameteri(tex, GL_TEXTURE_COMPARE_MODE, GL_COMPARE_REF_TO_TEXTURE);
  glTextureParameteri(tex, GL_TEXTURE_COMPARE_FUNC, GL_LEQUAL);
  return tex;
}

}  // namespace

void ShadowMaps::Create() { glCreateFramebuffers(1, &fbo_); }

void ShadowMaps::Delete() {
  for (auto& [side, set] : sets_) glDeleteTextures(1, &set.texture);
  sets_.clear();
  current_ = nullptr;
  glDeleteTextures(1, &stand_in_);
  glDeleteFramebuffers(1, &fbo_);
  stand_in_ = fbo_ = 0;
}

int ShadowMaps::AutoSize(int width, int height) {
  int want = 2 * std::max(width, height), side = 512;
  while (side < want && side < 2048) side *= 2;
  return side;
}

ShadowMaps::MapSet& ShadowMaps::Maps(int side, uint64_t geometry_version) {
  MapSet& set = sets_[side];
  if (set.texture == 0) set.texture = MakeDepthArray(side, kMaxShadows);
  // new meshes may sit where freed ones were (the same vertex array name): draw every layer again
  if (set.geometry_version != geometry_version) {
    set.valid.fill(false);
    set.geometry_version = geometry_version;
  }
  return set;
}

GLuint ShadowMaps::Texture() {
  if (current_ != nullptr) return current_->texture;
  if (stand_in_ == 0) stand_in_ = MakeDepthArray(1, 1);
  return stand_in_;
}

int ShadowMaps::Render(const RenderWorld& world, const CameraParams& camera,
                       const Eigen::AlignedBox3d& scene_box, const Resources& resources,
                       GLuint program, GLint mvp_location) {
  int count = 0;
  layer_.assign(world.lights.size(), -1);
  if (scene_box.isEmpty()) return 0;
  const int side = size_ > 0 ? size_ : AutoSize(camera.width, camera.height);
  Eigen::Matrix4d X_WG = camera.view.inverse();

  // receivers: the scene's box cut by the box of the view frustum
  Eigen::AlignedBox3d frustum_box;
  double far = std::min(camera.far, 1e4);
  for (int c = 0; c < 8; ++c) {
    double z = (c & 4) ? far : camera.near;
    double u = (c & 1) ? camera.width - 0.5 : -0.5;
    double v = (c & 2) ? camera.height - 0.5 : -0.5;
    // OpenCV ray through the image corner, into G (y and z flip)
    Eigen::Vector3d ray = camera.K.inverse() * Eigen::Vector3d(u, v, 1.0);
    Eigen::Vector3d p_G(ray.x() * z, -ray.y() * z, -z);
    frustum_box.extend((X_WG * p_G.homogeneous()).head<3>());
  }
  Eigen::AlignedBox3d receivers = scene_box.intersection(frustum_box);
  if (receivers.isEmpty()) receivers = scene_box;

  for (size_t li = 0; li < world.lights.size() && count < kMaxShadows; ++li) {
    const LightDesc& light = world.lights[li];
    if (!light.shadow || light.type == LightType::kPoint) continue;
    Eigen::Vector3d dir = light.direction.normalized();
    if (!dir.allFinite()) continue;
    Eigen::Matrix4d view, proj;
    Eigen::Vector2d texel;
    if (light.type == LightType::kDirectional) {
      Eigen::Vector3d c = receivers.center();
      double r = std::max(0.5 * receivers.diagonal().norm(), 1e-3);
      view = LookAlong(c, dir);
      // depth range over every caster: all corners of the scene box
      double zmin = std::numeric_limits<double>::max(), zmax = -zmin;
      for (int k = 0; k < 8; ++k) {
        double z = (view * scene_box.corner(Eigen::AlignedBox3d::CornerType(k)).homogeneous())(2);
        zmin = std::min(zmin, z);
        zmax = std::max(zmax, z);
      }
      double margin = 0.01 * (zmax - zmin) + 1e-3;
      proj = Ortho(-r, r, -r, r, -zmax - margin, -zmin + margin);
      texel = Eigen::Vector2d(2 * r / side, 0);
    } else {
      view = LookAlong(light.position, dir);
      double dmax = 0;
      for (int k = 0; k < 8; ++k) {
        dmax = std::max(
            dmax, (scene_box.corner(Eigen::AlignedBox3d::CornerType(k)) - light.position).norm());
      }
      double fovy = std::min(2 * std::max(light.outer_angle, light.inner_angle) + 0.05, 3.0);
      double f = dmax * 1.01 + 1e-3;
      double n = std::max(f * 1e-4, 1e-3);
      proj = Perspective(fovy, n, f);
      texel = Eigen::Vector2d(0, 2 * std::tan(fovy / 2) / side);
    }
    Eigen::Matrix4d view_proj = proj * view;
    // what this layer would draw; when its last drawing was the same, the layer stays
    draws_.clear();
    for (size_t i = 0; i < world.instances.size(); ++i) {
      const GpuMesh* mesh = resources.mesh(i);
      if (mesh == nullptr) continue;
      draws_.push_back(
          {mesh->vao, mesh->index_count, ToFloat(view_proj * world.instances[i].X_WV)});
    }
    MapSet& set = Maps(side, world.geometry_version);
    current_ = &set;
    if (reuse_ && set.valid[count] && set.drawn[count] == draws_) {
      ++layers_reused_;
    } else {
      glNamedFramebufferTextureLayer(fbo_, GL_DEPTH_ATTACHMENT, set.texture, 0, count);
      glBindFramebuffer(GL_FRAMEBUFFER, fbo_);
      glViewport(0, 0, side, side);
      glEnable(GL_DEPTH_TEST);
      glDepthFunc(GL_LESS);
      glDepthMask(GL_TRUE);
      glDisable(GL_CULL_FACE);
      glEnable(GL_POLYGON_OFFSET_FILL);
      glPolygonOffset(1.5f, 2.0f);
      const float one = 1.0f;
      glClearNamedFramebufferfv(fbo_, GL_DEPTH, 0, &one);
      glUseProgram(program);
      for (const Draw& d : draws_) {
        glUniformMatrix4fv(mvp_location, 1, GL_FALSE, d.mvp.data());
        glBindVertexArray(d.vao);
        glDrawElements(GL_TRIANGLES, d.count, GL_UNSIGNED_INT, nullptr);
      }
      glDisable(GL_POLYGON_OFFSET_FILL);
      set.drawn[count].swap(draws_);
      set.valid[count] = true;
      ++layers_drawn_;
    }
    // camera G -> light clip -> [0, 1]^3
    Eigen::Matrix4d bias = Eigen::Matrix4d::Identity() * 0.5;
    bias(3, 3) = 1;
    bias.block<3, 1>(0, 3).setConstant(0.5);
    matrix_[count] = ToFloat(bias * view_proj * X_WG);
    texel_[count] = texel.cast<float>();
    layer_[li] = count;
    ++count;
  }
  return count;
}

}  // namespace partsim::internal::raster
