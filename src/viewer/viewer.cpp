#include "viewer/viewer.h"

#include "core/error.h"
#include "core/log.h"
#include "gpu/context.h"
#include "gpu/pipeline.h"
#include "gpu/shader_compiler.h"
#include "viewer/display.h"
#include "viewer/imgui_layer.h"
#include "viewer/orbit_camera.h"
#include "viewer/swapchain.h"
#include "render/estimator.h"
#include "render/volume_source.h"
#include "viewer/ui.h"
#include "viewer/window.h"

#include <GLFW/glfw3.h>

#include <chrono>
#include <filesystem>
#include <memory>
#include <vector>

namespace plume::viewer {
namespace {

// Input gathered by GLFW callbacks (installed before ImGui's, which chain to them).
struct InputQueue {
  std::vector<int> keys;
  float scroll = 0.0f;
};
InputQueue g_input;

void onKey(GLFWwindow*, int key, int, int action, int) {
  if (action == GLFW_PRESS || action == GLFW_REPEAT) g_input.keys.push_back(key);
}
void onScroll(GLFWwindow*, double, double dy) { g_input.scroll += float(dy); }

int defaultWindowScale(int w, int h) { return std::max(1, std::min(1280 / std::max(1, w), 720 / std::max(1, h))); }

std::string screenshotPath(const ViewerOptions& o, int frame, int count) {
  if (!o.screenshot.empty()) return o.screenshot;
  return strf("plume_view_f%04d_%d.png", frame, count);
}

// EXR (linear, metadata) beside the PNG preview, as `plume render --png` writes them.
void saveScreenshot(const std::string& png, Image image, int spp, const ViewState& s, const std::string& device,
                    const CameraPose& pose) {
  const RenderSettings& rs = s.scene.render;
  setCommonMeta(image, {.mode = rs.mode, .spp = spp, .seed = rs.seed, .frame = s.frame, .device = device});
  image.meta["source"] = "plume view";
  image.meta["camera"] = strf("position %g %g %g look_at %g %g %g fov_y %g", pose.position.x, pose.position.y,
                              pose.position.z, pose.lookAt.x, pose.lookAt.y, pose.lookAt.z, pose.fovY);
  const std::string exr = std::filesystem::path(png).replace_extension(".exr").string();
  writeExr(exr, image);
  writePng(png, image, s.exposure);
}

class Viewer {
 public:
  explicit Viewer(const ViewerOptions& o);
  int run();

 private:
  void handleInput();
  void applyRequests(const UiRequests& req);
  void makeRenderer();
  void rebuildRenderer();
  void cameraMoved();
  void setFrame(int frame);
  void renderAndPresent(bool capture);

  const ViewerOptions& o_;
  ViewState s_;
  Camera sceneCamera_;
  std::unique_ptr<Window> window_;
  std::unique_ptr<gpu::Context> ctx_;
  std::unique_ptr<gpu::ShaderCompiler> compiler_;
  std::unique_ptr<Swapchain> swapchain_;
  std::unique_ptr<ImGuiLayer> ui_;
  std::unique_ptr<DisplayPass> display_;
  std::unique_ptr<ImageReadback> readback_;
  std::unique_ptr<gpu::GpuTimer> displayTimer_;
  std::unique_ptr<VolumeSource> volumes_;
  std::unique_ptr<Estimator> renderer_;
  OrbitCamera orbit_;
  ViewStats stats_;
  bool restart_ = true, continuous_ = false, haveImage_ = false, displayTimed_ = false;
  int historyFrame_ = 0;  // the animation frame of the renderer's history
  glm::dvec2 lastCursor_{0.0};
  int screenshots_ = 0;
  PassTimes rendererTimes_;
  // Host time of each phase of a frame, summed over a scripted run's second half (logged at its end).
  struct HostPhases {
    double input = 0, acquire = 0, renderer = 0, record = 0, present = 0;
    int frames = 0;
  } host_;
  bool timeHost_ = false;  // this frame's phases count
};

Viewer::Viewer(const ViewerOptions& o) : o_(o) {
  s_.scene = o.scene;
  const RenderSettings& rs = s_.scene.render;
  s_.frame = o.startFrame != 0 ? o.startFrame : rs.frameFirst;
  s_.playing = o.play;
  s_.sppPerFrame = o.sppPerFrame;
  s_.exposure = o.exposure;
  s_.showUi = !o.hideUi;
  sceneCamera_ = s_.scene.camera;
  const glm::ivec2 image(s_.scene.camera.width, s_.scene.camera.height);
  const int scale = o.windowScale > 0 ? o.windowScale : defaultWindowScale(image.x, image.y);
  window_ = std::make_unique<Window>(image * scale, "plume view - " + s_.scene.path);
  glfwSetKeyCallback(window_->handle(), onKey);
  glfwSetScrollCallback(window_->handle(), onScroll);

  gpu::ContextOptions co;
  co.deviceName = o.device;
  co.verbose = !o.quiet;
  co.instanceExtensions = window_->instanceExtensions();
  co.createSurface = [this](VkInstance instance) { return window_->createSurface(instance); };
  ctx_ = std::make_unique<gpu::Context>(co);
  compiler_ = std::make_unique<gpu::ShaderCompiler>(std::string(), gpu::ShaderCompiler::defaultCacheDir());
  swapchain_ = std::make_unique<Swapchain>(*ctx_, window_->framebufferSize());
  ui_ = std::make_unique<ImGuiLayer>(*ctx_, *window_, *swapchain_);
  display_ = std::make_unique<DisplayPass>(*ctx_, *compiler_);
  readback_ = std::make_unique<ImageReadback>(*ctx_);
  displayTimer_ = std::make_unique<gpu::GpuTimer>(*ctx_, 4);
  VolumeSourceOptions volumeOptions;
  volumeOptions.interactive = true;
  volumes_ = std::make_unique<VolumeSource>(*ctx_, s_.scene.medium(), volumeOptions);
  makeRenderer();
  orbit_.reset(sceneCamera_.poseAt(s_.frame));
  stats_.device = ctx_->deviceName();
  stats_.width = image.x;
  stats_.height = image.y;
  glfwGetCursorPos(window_->handle(), &lastCursor_.x, &lastCursor_.y);
}

void Viewer::cameraMoved() {
  s_.userCamera = true;
  s_.scene.camera.keys.clear();  // the orbit camera replaces the scene's camera path
  s_.scene.camera.base = orbit_.pose();
  restart_ = true;
  continuous_ = true;
}

void Viewer::setFrame(int frame) {
  const RenderSettings& rs = s_.scene.render;
  const int count = rs.frameLast - rs.frameFirst + 1;
  s_.frame = rs.frameFirst + ((frame - rs.frameFirst) % count + count) % count;  // wraps around
  if (!s_.userCamera) orbit_.reset(sceneCamera_.poseAt(s_.frame));
  restart_ = true;
  continuous_ = true;
}

void Viewer::handleInput() {
  GLFWwindow* w = window_->handle();
  glm::dvec2 cursor;
  glfwGetCursorPos(w, &cursor.x, &cursor.y);
  const glm::vec2 delta = glm::vec2(cursor - lastCursor_);
  lastCursor_ = cursor;
  const float viewHeight = float(window_->framebufferSize().y);
  if (!ui_->wantsMouse()) {
    const bool left = glfwGetMouseButton(w, GLFW_MOUSE_BUTTON_LEFT) == GLFW_PRESS;
    const bool shift = glfwGetKey(w, GLFW_KEY_LEFT_SHIFT) == GLFW_PRESS;
    const bool panButton = glfwGetMouseButton(w, GLFW_MOUSE_BUTTON_RIGHT) == GLFW_PRESS ||
                           glfwGetMouseButton(w, GLFW_MOUSE_BUTTON_MIDDLE) == GLFW_PRESS || (left && shift);
    if (delta != glm::vec2(0.0f) && panButton) {
      orbit_.pan(delta, viewHeight);
      cameraMoved();
    } else if (delta != glm::vec2(0.0f) && left) {
      orbit_.orbit(delta, viewHeight);
      cameraMoved();
    }
    if (g_input.scroll != 0.0f) {
      orbit_.zoom(g_input.scroll);
      cameraMoved();
    }
  }
  g_input.scroll = 0.0f;
  std::vector<int> keys;
  keys.swap(g_input.keys);
  if (ui_->wantsKeyboard()) return;
  UiRequests req;
  for (int key : keys) {
    switch (key) {
      case GLFW_KEY_SPACE: s_.playing = !s_.playing; break;
      case GLFW_KEY_RIGHT: req.step += 1; break;
      case GLFW_KEY_LEFT: req.step -= 1; break;
      case GLFW_KEY_HOME: setFrame(s_.scene.render.frameFirst); break;
      case GLFW_KEY_R: req.resetCamera = true; break;
      case GLFW_KEY_S: case GLFW_KEY_F12: req.screenshot = true; break;
      case GLFW_KEY_H: case GLFW_KEY_F1: s_.showUi = !s_.showUi; break;
      case GLFW_KEY_ESCAPE: case GLFW_KEY_Q: window_->requestClose(); break;
      default: break;
    }
  }
  applyRequests(req);
}

// The estimator of the working scene's mode (parsed here, once per change).
void Viewer::makeRenderer() {
  const EstimatorKind kind = estimatorKind(s_.scene.render);
  renderer_ = makeEstimator(kind, *ctx_, *compiler_, s_.scene);
  stats_.renderer = renderer_->name();
  stats_.usesSetting = [uses = estimatorTraits(kind).usesSetting, this](const std::string& key) {
    return uses(s_.scene, key);
  };
}

void Viewer::rebuildRenderer() {
  renderer_.reset();
  try {
    makeRenderer();
    s_.status.clear();
  } catch (const InputError& e) {
    s_.status = e.what();
    s_.scene.render.mode = "pt";  // back to what always works
    makeRenderer();
  }
  restart_ = true;
  continuous_ = false;
}

void Viewer::applyRequests(const UiRequests& req) {
  if (req.rebuildRenderer) rebuildRenderer();
  if (req.restart) {
    restart_ = true;
    continuous_ = false;
  }
  if (req.step != 0) setFrame(s_.frame + req.step);
  if (req.resetCamera) {
    s_.scene.camera = sceneCamera_;
    s_.userCamera = false;
    orbit_.reset(sceneCamera_.poseAt(s_.frame));
    restart_ = true;
    continuous_ = true;
  }
  if (req.screenshot && haveImage_) {
    const std::string path = screenshotPath(o_, s_.frame, ++screenshots_);
    saveScreenshot(path, renderer_->readImage(), renderer_->samplesSoFar(), s_, ctx_->deviceName(),
                   s_.scene.camera.poseAt(s_.frame));
    s_.status = "saved " + path + " and .exr";
    logInfo(s_.status);
  }
}

void Viewer::renderAndPresent(bool capture) {
  using Clock = std::chrono::steady_clock;
  Clock::time_point phase = Clock::now();  // the start of the phase being timed (host_)
  auto since = [&phase]() {
    const Clock::time_point now = Clock::now();
    const double ms = std::chrono::duration<double, std::milli>(now - phase).count();
    phase = now;
    return ms;
  };
  std::optional<uint32_t> index = swapchain_->acquire(window_->framebufferSize());
  if (!index) return;
  const double acquireMs = since();
  if (displayTimed_) {
    PassTimes t = displayTimer_->read();
    stats_.passes = rendererTimes_;
    stats_.passes.insert(stats_.passes.end(), t.begin(), t.end());
  }
  if (restart_) {
    // Temporal reuse follows the camera while the animation frame stays; a new animation frame (or
    // an edit that breaks continuity) starts a fresh history, as the viewer keeps only the current
    // frame's volume on the device.
    if (!continuous_ || s_.frame != historyFrame_) renderer_->forgetHistory();
    historyFrame_ = s_.frame;
    renderer_->setVolumes(volumes_->load(s_.frame), nullptr);
    renderer_->beginFrame(s_.frame);
    restart_ = false;
  }
  if (renderer_->samplesSoFar() < s_.maxSamples) {
    renderer_->addSamples(std::min(s_.sppPerFrame, s_.maxSamples - renderer_->samplesSoFar()));
    rendererTimes_ = renderer_->lastPassTimes();
    display_->setSource(renderer_->accumulation(), s_.scene.camera.width, s_.scene.camera.height);
    haveImage_ = true;
  }
  stats_.samples = renderer_->samplesSoFar();
  const double rendererMs = since();
  VkCommandBuffer cmd = swapchain_->commandBuffer();
  const VkExtent2D extent = swapchain_->extent();
  displayTimer_->reset(cmd);
  display_->record(cmd, swapchain_->image(*index), extent, swapchain_->bgra(), s_.exposure, displayTimer_.get());
  displayTimed_ = true;
  VkRenderPassBeginInfo rb{VK_STRUCTURE_TYPE_RENDER_PASS_BEGIN_INFO};
  rb.renderPass = swapchain_->renderPass();
  rb.framebuffer = swapchain_->framebuffer(*index);
  rb.renderArea.extent = extent;
  vkCmdBeginRenderPass(cmd, &rb, VK_SUBPASS_CONTENTS_INLINE);
  ui_->record(cmd);
  vkCmdEndRenderPass(cmd);
  if (capture) readback_->record(cmd, swapchain_->image(*index), extent);
  const double recordMs = since();
  swapchain_->submitAndPresent(*index, window_->framebufferSize());
  if (timeHost_) {
    host_.acquire += acquireMs;
    host_.renderer += rendererMs;
    host_.record += recordMs;
    host_.present += since();
    ++host_.frames;
  }
}

int Viewer::run() {
  const bool scripted = o_.scriptedFrames > 0;
  if (scripted && !o_.captureWindow.empty() && !swapchain_->canReadBack()) {
    throw DeviceError(ctx_->deviceName() + ": swapchain images cannot be read back (--capture-window)");
  }
  auto last = std::chrono::steady_clock::now();
  for (int n = 0; !window_->shouldClose(); ++n) {
    if (scripted && n >= o_.scriptedFrames) break;
    const bool idle = !s_.playing && renderer_->samplesSoFar() >= s_.maxSamples && !restart_;
    if (idle && !scripted) glfwWaitEventsTimeout(0.05);  // nothing to add: do not spin
    else glfwPollEvents();
    handleInput();
    if (s_.playing && n > 0) setFrame(s_.frame + 1);
    ui_->newFrame();
    if (s_.showUi) applyRequests(drawUi(s_, stats_));
    ui_->endFrame();
    timeHost_ = scripted && n >= o_.scriptedFrames / 2;
    if (timeHost_) host_.input += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - last).count();
    renderAndPresent(scripted && n == o_.scriptedFrames - 1 && !o_.captureWindow.empty());
    const auto now = std::chrono::steady_clock::now();
    const double ms = std::chrono::duration<double, std::milli>(now - last).count();
    last = now;
    stats_.frameMs = n == 0 ? ms : 0.9 * stats_.frameMs + 0.1 * ms;
    stats_.fps = stats_.frameMs > 0 ? 1000.0 / stats_.frameMs : 0.0;
  }
  swapchain_->waitForFrame();
  if (scripted) {
    logInfo(strf("view: %d frames, %.2f ms/frame (%.1f fps) at %dx%d, window %ux%u, %s", o_.scriptedFrames,
                 stats_.frameMs, stats_.fps, stats_.width, stats_.height, swapchain_->extent().width,
                 swapchain_->extent().height, stats_.renderer.c_str()));
    // The GPU passes of the last frame as the panel shows them (the renderer's, then the display's).
    PassTimes passes = rendererTimes_;
    const PassTimes display = displayTimer_->read();
    passes.insert(passes.end(), display.begin(), display.end());
    logInfo("view: last frame's passes: " + passTimesText(passes));
    if (host_.frames > 0) {
      const double k = 1.0 / host_.frames;
      logInfo(strf("view: host ms a frame (the last %d frames): events and panel %.2f, acquire %.2f, renderer %.2f, "
                   "recording %.2f, submit and present %.2f", host_.frames, host_.input * k, host_.acquire * k,
                   host_.renderer * k, host_.record * k, host_.present * k));
    }
    if (!o_.screenshot.empty()) {
      saveScreenshot(o_.screenshot, renderer_->readImage(), renderer_->samplesSoFar(), s_, ctx_->deviceName(),
                     s_.scene.camera.poseAt(s_.frame));
      logInfo("view: wrote " + o_.screenshot);
    }
    if (!o_.captureWindow.empty()) {
      const VkExtent2D e = readback_->extent();
      writeRgb8Png(o_.captureWindow, int(e.width), int(e.height), readback_->pixels(swapchain_->bgra()));
      logInfo("view: wrote " + o_.captureWindow);
    }
  }
  return kExitOk;
}

}  // namespace

int runViewer(const ViewerOptions& options) {
  Viewer viewer(options);
  return viewer.run();
}

}  // namespace plume::viewer
