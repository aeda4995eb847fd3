#include "footfall/viewer/query_view.h"

namespace footfall::viewer {

QueryView RunQuery(const TerrainGrid& grid, const QuerySpec& spec) {
  QueryView view;
  view.spec = spec;
  view.traced = true;
  if (spec.op == QueryOp::kNext) {
    view.result = grid.Next({spec.point, spec.direction}, spec.tolerance, &view.trace);
  } else {
    view.result = grid.Snap(spec.point, &view.trace);
  }
  return view;
}

QueryView FromRecent(const RecentQuery& query, const TerrainGrid* grid) {
  QuerySpec spec;
  spec.op = query.op;
  spec.point = query.point;
  spec.direction = query.direction;
  spec.tolerance = query.tolerance;
  QueryView view;
  if (grid && !grid->empty()) {
    view = RunQuery(*grid, spec);
    const Foothold& local = view.result;
    const Foothold& served = query.result;
    view.other_terrain = local.status != served.status ||
                         (served.status == Status::kOk &&
                          (local.point != served.point || local.index != served.index));
    if (view.other_terrain) view.traced = false, view.trace = QueryTrace{};
  }
  view.spec = spec;
  view.result = query.result;
  view.live = true;
  view.sequence = query.sequence;
  if (!view.traced) {
    view.trace.ideal = spec.op == QueryOp::kNext ? spec.point + spec.direction : spec.point;
  }
  return view;
}

}  // namespace footfall::viewer
