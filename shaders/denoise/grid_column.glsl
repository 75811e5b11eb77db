// Column-by-column tap visits for the spaces whose columns differ only in their row count
// (included by cartesian_grid.glsl and visual_polar_grid.glsl after their Grid and grid_rows).
// Filter loops visit taps column by column: the row count of a column (divisions and a floor in
// Visual-Polar) is then computed once per column instead of once or twice per tap, which is most
// of a VP tap's cost on lavapipe. A tap found this way is exactly grid_tap's (same expression).
#ifndef FOVEA_DENOISE_GRID_COLUMN_GLSL
#define FOVEA_DENOISE_GRID_COLUMN_GLSL

struct GridColumn {
    int col;
    int rows;        // rows of `col`
    int rows_here;   // rows of the centre's column
};

// The column `dx` texels away from t's; false when that leaves the grid.
bool grid_column(Grid g, ivec2 t, int rows_here, int dx, out GridColumn c) {
    c.col = t.x + dx;
    c.rows_here = rows_here;
    c.rows = (dx == 0 || c.col < 0 || c.col >= g.size.x) ? rows_here : grid_rows(g, c.col);
    return c.col >= 0 && c.col < g.size.x;
}

#endif
