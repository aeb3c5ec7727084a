// Which goals of the map a tree node names: what the map rings when the node is selected
// (js/map/goal_highlight.js).
//
// MoveTo names its goal in `location` (cyborg/robot/move_to.py; behavior3editor's trees in
// /work/shared/trees write `"properties": {"location": "room1"}`); nodes of other projects say
// `goal`, `goal_name`, `target` or `dock`. Those come first, then every other property whose
// value is text: the map takes the first that is the name of one of its goals, docks or homes,
// so a node of any kind that names a goal in its properties has it ringed.

const GOAL_PROPERTIES = ["location", "goal", "goal_name", "goalName", "target", "dock"];

export function goalNames(node) {
  const properties = node && node.properties && typeof node.properties === "object" ? node.properties : {};
  const names = [];
  const add = (value) => {
    if (typeof value === "string" && value.trim() && !names.includes(value.trim())) names.push(value.trim());
  };
  for (const key of GOAL_PROPERTIES) add(properties[key]);
  for (const value of Object.values(properties)) add(value);
  return names;
}
