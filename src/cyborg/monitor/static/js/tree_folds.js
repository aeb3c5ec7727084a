// The nodes folded and unfolded by hand, kept per tree: a runner of a mode file shows another
// tree at each change of mode, and coming back to a mode's tree brings back its folds. Trees
// are told apart by their runner's namespace and title; a new version of the same tree (a
// reload) keeps the folds it has.

export class TreeFolds {
  constructor() {
    this.kept = new Map();
  }

  // `page` leaves the tree `page.title` of `page.ns` for the tree `title` of `ns`: its
  // `folded` and `opened` sets are kept and the new tree's come back (empty if never shown).
  switchTree(page, ns, title) {
    const left = `${page.ns}\u0000${page.title}`;
    const key = `${ns}\u0000${title}`;
    if (key === left) return;
    this.kept.set(left, { folded: page.folded, opened: page.opened });
    const kept = this.kept.get(key);
    page.folded = kept ? kept.folded : new Set();
    page.opened = kept ? kept.opened : new Set();
  }
}
