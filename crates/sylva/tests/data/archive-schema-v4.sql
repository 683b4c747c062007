-- table schema_version on schema_version
CREATE TABLE schema_version (version INTEGER NOT NULL)

-- table sessions on sessions
CREATE TABLE sessions (
    id INTEGER PRIMARY KEY,
    mode TEXT NOT NULL,
    model TEXT NOT NULL,
    title TEXT NOT NULL,
    state TEXT NOT NULL,
    created TEXT NOT NULL
)

-- table plants on plants
CREATE TABLE plants (
    id INTEGER PRIMARY KEY,
    session INTEGER REFERENCES sessions(id),
    model TEXT NOT NULL,
    genome TEXT NOT NULL,
    seed INTEGER NOT NULL,
    operator TEXT NOT NULL,
    settings TEXT NOT NULL,
    created TEXT NOT NULL
)

-- index plants_session on plants
CREATE INDEX plants_session ON plants(session)

-- table parents on parents
CREATE TABLE parents (
    child INTEGER NOT NULL REFERENCES plants(id),
    ord INTEGER NOT NULL,
    parent INTEGER NOT NULL REFERENCES plants(id),
    dominance REAL NOT NULL,
    PRIMARY KEY (child, ord)
)

-- index sqlite_autoindex_parents_1 on parents
-- (made by SQLite)

-- index parents_parent on parents
CREATE INDEX parents_parent ON parents(parent)

-- table meshes on meshes
CREATE TABLE meshes (
    plant INTEGER PRIMARY KEY REFERENCES plants(id),
    glb BLOB NOT NULL
)

-- table scenes on scenes
CREATE TABLE scenes (
    id INTEGER PRIMARY KEY,
    glb BLOB NOT NULL
)

-- table steps on steps
CREATE TABLE steps (
    id INTEGER PRIMARY KEY,
    session INTEGER NOT NULL REFERENCES sessions(id),
    seq INTEGER NOT NULL,
    action TEXT NOT NULL,
    before TEXT NOT NULL,
    after TEXT NOT NULL,
    undone INTEGER NOT NULL DEFAULT 0,
    created TEXT NOT NULL,
    UNIQUE (session, seq)
)

-- index sqlite_autoindex_steps_1 on steps
-- (made by SQLite)

-- table runs on runs
CREATE TABLE runs (
    id INTEGER PRIMARY KEY,
    session INTEGER NOT NULL REFERENCES sessions(id),
    config TEXT NOT NULL,
    checkpoint TEXT,
    status TEXT NOT NULL,
    generation INTEGER NOT NULL,
    generations INTEGER NOT NULL,
    terms TEXT NOT NULL DEFAULT '[]',
    error TEXT
)

-- table run_generations on run_generations
CREATE TABLE run_generations (
    run INTEGER NOT NULL REFERENCES runs(id),
    generation INTEGER NOT NULL,
    best REAL NOT NULL,
    mean REAL NOT NULL,
    best_terms TEXT NOT NULL,
    plant INTEGER REFERENCES plants(id),
    PRIMARY KEY (run, generation)
)

-- index sqlite_autoindex_run_generations_1 on run_generations
-- (made by SQLite)

-- table run_checkpoints on run_checkpoints
CREATE TABLE run_checkpoints (
    run INTEGER NOT NULL REFERENCES runs(id),
    generation INTEGER NOT NULL,
    checkpoint TEXT NOT NULL,
    PRIMARY KEY (run, generation)
)

-- index sqlite_autoindex_run_checkpoints_1 on run_checkpoints
-- (made by SQLite)

-- table map_cells on map_cells
CREATE TABLE map_cells (
    run INTEGER NOT NULL REFERENCES runs(id),
    cell INTEGER NOT NULL,
    plant INTEGER NOT NULL REFERENCES plants(id),
    fitness REAL NOT NULL,
    descriptors TEXT NOT NULL,
    PRIMARY KEY (run, cell)
)

-- index sqlite_autoindex_map_cells_1 on map_cells
-- (made by SQLite)

-- table pictures on pictures
CREATE TABLE pictures (
    session INTEGER NOT NULL REFERENCES sessions(id),
    view TEXT NOT NULL,
    bytes BLOB NOT NULL,
    PRIMARY KEY (session, view)
)

-- index sqlite_autoindex_pictures_1 on pictures
-- (made by SQLite)

-- table run_trials on run_trials
CREATE TABLE run_trials (
    run INTEGER PRIMARY KEY REFERENCES runs(id),
    log TEXT NOT NULL,
    ended TEXT NOT NULL
)

-- table trial_generations on trial_generations
CREATE TABLE trial_generations (
    run INTEGER NOT NULL REFERENCES runs(id),
    model TEXT NOT NULL,
    runoff INTEGER NOT NULL,
    generation INTEGER NOT NULL,
    best REAL NOT NULL,
    mean REAL NOT NULL,
    iou REAL NOT NULL,
    plant INTEGER REFERENCES plants(id),
    PRIMARY KEY (run, model, generation)
)

-- index sqlite_autoindex_trial_generations_1 on trial_generations
-- (made by SQLite)
