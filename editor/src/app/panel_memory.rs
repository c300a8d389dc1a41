//! The dock layout — which panes sit where, their split shares and open tabs — kept per user
//! beside the view memory (`panels.json` in the recovery folder), never in a document: how
//! an artist arranges the editor is not an edit.
//!
//! The file holds our own small description of the layout, not egui_tiles' internal tree, so
//! a hostile file cannot hand the dock a cycle, a dangling tile id or a reused id counter:
//! the tree is rebuilt through egui_tiles' own `insert_*` calls after every pane is checked
//! to appear exactly once, the nesting to stay shallow and every share to be a sane number.
//! A file that fails any check is ignored as a whole (the default layout is used) and the
//! status bar names the problem; failing to store it never interrupts the artist.

use std::path::PathBuf;

use egui_tiles::{Container, GridLayout, LinearDir, Tile, TileId, Tiles, Tree};
use serde::{Deserialize, Serialize};

use super::Pane;

/// One tile of a stored layout.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum SavedTile {
    Pane {
        pane: Pane,
    },
    Tabs {
        /// Index of the open tab among `children`.
        active: usize,
        children: Vec<SavedTile>,
    },
    Linear {
        horizontal: bool,
        /// One share per child (egui_tiles divides the space in these proportions).
        shares: Vec<f32>,
        children: Vec<SavedTile>,
    },
    Grid {
        /// `None`: as many columns as fit.
        columns: Option<usize>,
        children: Vec<SavedTile>,
    },
}

/// Deeper nesting than any arrangement of eight panes needs.
const MAX_DEPTH: usize = 16;
/// Share ratios beyond this would hide a pane; egui_tiles itself keeps them far smaller.
const MAX_SHARE: f32 = 1e4;
/// More grid columns than panes exist is nonsense.
const MAX_GRID_COLUMNS: usize = 8;

impl SavedTile {
    /// The layout `tree` shows, or `None` when it is empty.
    pub fn of(tree: &Tree<Pane>) -> Option<Self> {
        Self::of_tile(&tree.tiles, tree.root?, 0)
    }

    fn of_tile(tiles: &Tiles<Pane>, id: TileId, depth: usize) -> Option<Self> {
        // egui_tiles' own trees are acyclic; the depth guard only keeps a bug from recursing
        // without end.
        if depth > MAX_DEPTH {
            return None;
        }
        let children = |ids: &mut dyn Iterator<Item = &TileId>| -> Vec<(TileId, SavedTile)> {
            ids.filter(|child| tiles.is_visible(**child))
                .filter_map(|child| Some((*child, Self::of_tile(tiles, *child, depth + 1)?)))
                .collect()
        };
        Some(match tiles.get(id)? {
            Tile::Pane(pane) => Self::Pane { pane: *pane },
            Tile::Container(Container::Tabs(tabs)) => {
                let kept = children(&mut tabs.children.iter());
                let active = kept
                    .iter()
                    .position(|(child, _)| Some(*child) == tabs.active)
                    .unwrap_or(0);
                Self::Tabs {
                    active,
                    children: kept.into_iter().map(|(_, tile)| tile).collect(),
                }
            }
            Tile::Container(Container::Linear(linear)) => {
                let kept = children(&mut linear.children.iter());
                Self::Linear {
                    horizontal: linear.dir == LinearDir::Horizontal,
                    shares: kept
                        .iter()
                        .map(|(child, _)| linear.shares[*child])
                        .collect(),
                    children: kept.into_iter().map(|(_, tile)| tile).collect(),
                }
            }
            Tile::Container(Container::Grid(grid)) => Self::Grid {
                columns: match grid.layout {
                    GridLayout::Auto => None,
                    GridLayout::Columns(columns) => Some(columns),
                },
                children: children(&mut grid.children())
                    .into_iter()
                    .map(|(_, tile)| tile)
                    .collect(),
            },
        })
    }

    /// The dock this layout describes, or what is wrong with it.
    pub fn to_tree(&self) -> Result<Tree<Pane>, String> {
        let mut seen = Vec::new();
        self.check(0, &mut seen)?;
        for pane in Pane::ALL {
            if !seen.contains(&pane) {
                return Err(format!("the {} pane is missing", pane.title()));
            }
        }
        let mut tiles = Tiles::default();
        let root = self.insert(&mut tiles);
        Ok(Tree::new(egui::Id::unique("hairloom layout"), root, tiles))
    }

    fn check(&self, depth: usize, seen: &mut Vec<Pane>) -> Result<(), String> {
        if depth > MAX_DEPTH {
            return Err(format!("panes nested deeper than {MAX_DEPTH} levels"));
        }
        let children = match self {
            Self::Pane { pane } => {
                if seen.contains(pane) {
                    return Err(format!("the {} pane appears twice", pane.title()));
                }
                seen.push(*pane);
                return Ok(());
            }
            Self::Tabs { active, children } => {
                if !children.is_empty() && *active >= children.len() {
                    return Err(format!(
                        "open tab {active} of a group of {} tabs",
                        children.len()
                    ));
                }
                children
            }
            Self::Linear {
                shares, children, ..
            } => {
                if shares.len() != children.len() {
                    return Err(format!(
                        "{} shares for a split of {} panes",
                        shares.len(),
                        children.len()
                    ));
                }
                if let Some(share) = shares
                    .iter()
                    .find(|s| !(s.is_finite() && **s > 0.0 && **s <= MAX_SHARE))
                {
                    return Err(format!(
                        "split share {share} (a share must be in (0, {MAX_SHARE}])"
                    ));
                }
                children
            }
            Self::Grid { columns, children } => {
                if let Some(columns) = columns
                    && !(1..=MAX_GRID_COLUMNS).contains(columns)
                {
                    return Err(format!(
                        "a grid of {columns} columns (1 to {MAX_GRID_COLUMNS})"
                    ));
                }
                children
            }
        };
        if children.is_empty() {
            return Err("an empty pane group".into());
        }
        children
            .iter()
            .try_for_each(|child| child.check(depth + 1, seen))
    }

    /// Inserts this (checked) tile and its children; returns its id.
    fn insert(&self, tiles: &mut Tiles<Pane>) -> TileId {
        let mut insert_children =
            |children: &[SavedTile]| children.iter().map(|c| c.insert(tiles)).collect::<Vec<_>>();
        match self {
            Self::Pane { pane } => tiles.insert_pane(*pane),
            Self::Tabs { active, children } => {
                let ids = insert_children(children);
                let open = ids[*active];
                let id = tiles.insert_tab_tile(ids);
                if let Some(Tile::Container(Container::Tabs(tabs))) = tiles.get_mut(id) {
                    tabs.set_active(open);
                }
                id
            }
            Self::Linear {
                horizontal,
                shares,
                children,
            } => {
                let ids = insert_children(children);
                let id = if *horizontal {
                    tiles.insert_horizontal_tile(ids.clone())
                } else {
                    tiles.insert_vertical_tile(ids.clone())
                };
                if let Some(Tile::Container(Container::Linear(linear))) = tiles.get_mut(id) {
                    for (child, share) in ids.into_iter().zip(shares) {
                        linear.shares.set_share(child, *share);
                    }
                }
                id
            }
            Self::Grid { columns, children } => {
                let ids = insert_children(children);
                let id = tiles.insert_grid_tile(ids);
                if let (Some(columns), Some(Tile::Container(Container::Grid(grid)))) =
                    (columns, tiles.get_mut(id))
                {
                    grid.layout = GridLayout::Columns(*columns);
                }
                id
            }
        }
    }
}

/// The user's dock layout on disk.
pub struct PanelMemory {
    file: PathBuf,
    stored: Option<SavedTile>,
}

impl PanelMemory {
    /// Larger files are not read (the default layout takes under a kilobyte).
    const MAX_FILE_BYTES: u64 = 64 * 1024;

    /// The memory kept in `file`, the layout stored there (`None` when there is none yet)
    /// and, when the file could not be used, why.
    pub fn load(file: PathBuf) -> (Self, Option<Tree<Pane>>, Option<String>) {
        // Until the artist rearranges something, the default layout counts as stored: no
        // file is written for a layout nobody chose.
        let default = SavedTile::of(&super::default_layout());
        let (stored, tree, problem) = match Self::read(&file) {
            Ok(None) => (default, None, None),
            Ok(Some(saved)) => match saved.to_tree() {
                Ok(tree) => (Some(saved), Some(tree), None),
                Err(why) => (default, None, Some(why)),
            },
            Err(why) => (default, None, Some(why)),
        };
        let problem =
            problem.map(|why| format!("{} ignored (default layout): {why}", file.display()));
        (Self { file, stored }, tree, problem)
    }

    fn read(file: &std::path::Path) -> Result<Option<SavedTile>, String> {
        use hairloom_core::io::input_files::{InputFileError, read_regular_file};
        // The same rules as every input file: a FIFO cannot block the start, a link to a
        // device is refused, and the cap holds while reading.
        let bytes = match read_regular_file(file, Self::MAX_FILE_BYTES, "a dock layout") {
            Ok(bytes) => bytes,
            Err(InputFileError::Io { source, .. })
                if source.kind() == std::io::ErrorKind::NotFound =>
            {
                return Ok(None);
            }
            Err(error) => return Err(error.to_string()),
        };
        // serde_json's recursion limit stops a nesting bomb before `check` sees it.
        serde_json::from_slice(&bytes)
            .map(Some)
            .map_err(|e| e.to_string())
    }

    /// Stores `tree`'s layout when it differs from the stored one.
    pub fn remember(&mut self, tree: &Tree<Pane>) {
        let Some(saved) = SavedTile::of(tree) else {
            return;
        };
        if self.stored.as_ref() == Some(&saved) || saved.to_tree().is_err() {
            return;
        }
        let Ok(text) = serde_json::to_vec_pretty(&saved) else {
            return;
        };
        if let Some(dir) = self.file.parent() {
            let _ = super::recovery::create_private_dir(dir);
        }
        let _ = hairloom_core::io::project::write_atomic(&self.file, &text, |_| {});
        self.stored = Some(saved);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::app::default_layout;

    /// The default layout with the left column's shares changed, the history pane moved into
    /// the right tab group and the scene tab open.
    fn rearranged() -> Tree<Pane> {
        let mut tree = default_layout();
        let pane_id = |tree: &Tree<Pane>, pane: Pane| {
            tree.tiles
                .iter()
                .find(|(_, tile)| matches!(tile, Tile::Pane(p) if *p == pane))
                .map(|(id, _)| *id)
                .expect("pane")
        };
        let history = pane_id(&tree, Pane::History);
        let scene = pane_id(&tree, Pane::Scene);
        let styling = pane_id(&tree, Pane::Styling);
        let right = tree.tiles.parent_of(styling).expect("right tabs");
        tree.move_tile_to_container(history, right, 1, true);
        tree.simplify_children_of_tile(tree.root.expect("root"), &Default::default());
        if let Some(Tile::Container(Container::Tabs(tabs))) = tree.tiles.get_mut(right) {
            tabs.set_active(scene);
        }
        let root = tree.root.expect("root");
        if let Some(Tile::Container(Container::Linear(linear))) = tree.tiles.get_mut(root) {
            let first = linear.children[0];
            linear.shares.set_share(first, 2.25);
        }
        tree
    }

    #[test]
    fn a_rearranged_layout_comes_back_in_the_next_session() {
        let dir = tempfile::tempdir().expect("temp dir");
        let file = dir.path().join("panels.json");
        let (mut memory, tree, problem) = PanelMemory::load(file.clone());
        assert!(tree.is_none() && problem.is_none());
        // The default layout is not written: nobody chose it.
        memory.remember(&default_layout());
        assert!(!file.exists());
        let arranged = rearranged();
        let saved = SavedTile::of(&arranged).expect("layout");
        assert_ne!(Some(saved.clone()), SavedTile::of(&default_layout()));
        memory.remember(&arranged);
        let (_, tree, problem) = PanelMemory::load(file.clone());
        assert_eq!(problem, None);
        let tree = tree.expect("stored layout");
        assert_eq!(SavedTile::of(&tree), Some(saved.clone()));
        // The open tab and the changed share are part of what came back.
        let SavedTile::Linear {
            shares, children, ..
        } = &saved
        else {
            panic!("root is a split: {saved:?}");
        };
        assert_eq!(shares[0], 2.25);
        let Some(SavedTile::Tabs { active, children }) = children.last() else {
            panic!("right column is tabs: {saved:?}");
        };
        assert_eq!(children[*active], SavedTile::Pane { pane: Pane::Scene });
        assert!(children.contains(&SavedTile::Pane {
            pane: Pane::History
        }));
        // An unchanged layout is not written again.
        std::fs::remove_file(&file).expect("remove");
        memory.remember(&tree);
        assert!(!file.exists());
    }

    #[test]
    fn hostile_layout_files_fall_back_to_the_default_and_say_why() {
        let dir = tempfile::tempdir().expect("temp dir");
        let file = dir.path().join("panels.json");
        let good = serde_json::to_value(SavedTile::of(&default_layout())).expect("json");
        let mutate = |edit: &dyn Fn(&mut serde_json::Value)| {
            let mut value = good.clone();
            edit(&mut value);
            value.to_string().into_bytes()
        };
        let cases: Vec<(Vec<u8>, &str)> = vec![
            (
                mutate(&|v| {
                    v["children"][1] = serde_json::json!({"kind": "pane", "pane": "Tools"})
                }),
                "the Tools pane appears twice",
            ),
            (
                mutate(&|v| v["children"].as_array_mut().expect("children").truncate(2)),
                "shares for a split of",
            ),
            (
                mutate(&|v| {
                    v["children"].as_array_mut().expect("children").remove(1);
                    v["shares"].as_array_mut().expect("shares").remove(1);
                }),
                "the Viewport pane is missing",
            ),
            (
                mutate(&|v| v["shares"][0] = (-1.0).into()),
                "split share -1",
            ),
            (mutate(&|v| v["shares"][0] = 1e30.into()), "split share"),
            (
                mutate(&|v| v["children"][2]["active"] = 99.into()),
                "open tab 99",
            ),
            (
                mutate(&|v| v["children"][2]["children"] = serde_json::json!([])),
                "empty pane group",
            ),
            (b"{{{{".to_vec(), "key must be a string"),
            (
                format!(
                    "{}{}",
                    r#"{"kind":"tabs","active":0,"children":["#.repeat(1000),
                    "]}".repeat(1000)
                )
                .into_bytes(),
                "recursion limit",
            ),
            (vec![b' '; 100 * 1024], "larger than the cap of 65536 bytes"),
        ];
        for (bytes, expected) in cases {
            std::fs::write(&file, &bytes).expect("write");
            let (_, tree, problem) = PanelMemory::load(file.clone());
            assert!(tree.is_none(), "{expected}: a layout was used");
            let problem = problem.expect("a problem is named");
            assert!(
                problem.contains(expected) && problem.contains("panels.json"),
                "expected {expected:?} in {problem:?}"
            );
        }
        // Special files: a FIFO blocked the start forever, a link to /dev/zero was read until
        // memory ran out. Both are refused at once, by name.
        crate::app::test_support::make_fifo(&file);
        let fifo = file.clone();
        let problem = crate::app::test_support::returns_promptly(move || PanelMemory::load(fifo).2)
            .expect("a problem is named");
        assert!(problem.contains("a FIFO"), "{problem}");
        std::fs::remove_file(&file).expect("remove");
        std::os::unix::fs::symlink("/dev/zero", &file).expect("link");
        let (_, tree, problem) = PanelMemory::load(file.clone());
        assert!(tree.is_none());
        let problem = problem.expect("a problem is named");
        assert!(problem.contains("a device"), "{problem}");
        // Nested too deep for the dock, yet within serde's limit.
        let mut deep = SavedTile::Pane { pane: Pane::Tools };
        for _ in 0..20 {
            deep = SavedTile::Tabs {
                active: 0,
                children: vec![deep],
            };
        }
        assert!(
            deep.to_tree()
                .expect_err("too deep")
                .contains("nested deeper")
        );
    }
}
