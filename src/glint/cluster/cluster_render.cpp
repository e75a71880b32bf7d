#include "glint/cluster/cluster_render.h"

#include "glint/cluster/worker.h"

namespace glint::cluster {

ClusterRender::ClusterRender() = default;

int ClusterRender::serve(const RenderJobSpec& spec) { return serveTiles(session_, spec); }

void ClusterRender::distribute(RenderJobSpec& spec) {
  coordinator_ =
      std::make_unique<Coordinator>(session_, spec.scene, spec.threads, spec.cancelSignal);
  spec.renderStep = [this](const Scene& scene, const RenderOptions& options, Film& film,
                           RenderStats& stats) {
    coordinator_->render(scene, options, film, stats);
  };
}

int ClusterRender::finish(int status) {
  const bool orderly = coordinator_ ? coordinator_->release(status) : true;
  return session_.finish(status, orderly);
}

const ClusterFigures& ClusterRender::figures() const {
  return coordinator_ ? coordinator_->figures() : none_;
}

}  // namespace glint::cluster
