NAME        
ROWS
 N  Obj     
 L  c3_o2_3_1__0
 L  c3_o3_4_1__1
 L  c4_r1__2
 L  c4_r2__3
 G  c5_4    
 E  c8_o1__5
 G  c9_0_o2__6
 G  c9_0_o3__7
 G  c9_1_o2__8
 L  c10_o2__9
 L  c10_o3__10
 G  c11_0_o2__11
 G  c12_0_o3__12
 G  c11_1_o2__13
COLUMNS
    MARK0000  'MARKER'                 'INTORG'
    X_o1_goal_r1_r1_top_top__t1  Obj       1
    X_o1_goal_r1_r1_top_top__t1  c3_o2_3_1__0  -1
    X_o1_goal_r1_r1_top_top__t1  c3_o3_4_1__1  -1
    X_o1_goal_r1_r1_top_top__t1  c4_r1__2  1
    X_o1_goal_r1_r1_top_top__t1  c5_4      1
    X_o1_goal_r1_r1_top_top__t1  c8_o1__5  1
    X_o1_goal_r1_r1_top_top__t1  c9_0_o2__6  -1
    X_o1_goal_r1_r1_top_top__t1  c9_0_o3__7  -1
    X_o1_goal_r1_r1_top_top__t1  c11_0_o2__11  -1
    X_o1_goal_r1_r2_top_side__t1  Obj       1
    X_o1_goal_r1_r2_top_side__t1  c3_o2_3_1__0  -1
    X_o1_goal_r1_r2_top_side__t1  c4_r1__2  1
    X_o1_goal_r1_r2_top_side__t1  c4_r2__3  1
    X_o1_goal_r1_r2_top_side__t1  c5_4      1
    X_o1_goal_r1_r2_top_side__t1  c8_o1__5  1
    X_o1_goal_r1_r2_top_side__t1  c9_1_o2__8  -1
    X_o1_goal_r1_r2_top_side__t1  c11_1_o2__13  -1
    X_o1_goal_r2_r2_side_side__t1  Obj       1
    X_o1_goal_r2_r2_side_side__t1  c4_r2__3  1
    X_o1_goal_r2_r2_side_side__t1  c5_4      1
    X_o1_goal_r2_r2_side_side__t1  c8_o1__5  1
    X_o2_start_r1_r1_top_top__t1  Obj       1
    X_o2_start_r1_r1_top_top__t1  c3_o2_3_1__0  1
    X_o2_start_r1_r1_top_top__t1  c4_r1__2  1
    X_o2_start_r1_r1_top_top__t1  c5_4      1
    X_o2_start_r1_r1_top_top__t1  c9_0_o2__6  1
    X_o2_start_r1_r1_top_top__t1  c9_1_o2__8  1
    X_o2_start_r1_r1_top_top__t1  c10_o2__9  1
    X_o2_start_r1_r1_top_top__t1  c11_0_o2__11  -1
    X_o2_start_r1_r1_top_top__t1  c11_1_o2__13  -1
    X_o3_start_r2_r2_side_side__t1  Obj       1
    X_o3_start_r2_r2_side_side__t1  c3_o3_4_1__1  1
    X_o3_start_r2_r2_side_side__t1  c4_r2__3  1
    X_o3_start_r2_r2_side_side__t1  c5_4      1
    X_o3_start_r2_r2_side_side__t1  c9_0_o3__7  1
    X_o3_start_r2_r2_side_side__t1  c10_o3__10  1
    X_o3_start_r2_r2_side_side__t1  c12_0_o3__12  -1
    MARK0001  'MARKER'                 'INTEND'
RHS
    RHS_V     c4_r1__2  1
    RHS_V     c4_r2__3  1
    RHS_V     c5_4      1
    RHS_V     c8_o1__5  1
    RHS_V     c10_o2__9  1
    RHS_V     c10_o3__10  1
    RHS_V     c11_0_o2__11  -1
    RHS_V     c12_0_o3__12  -1
    RHS_V     c11_1_o2__13  -1
BOUNDS
 BV BOUND     X_o1_goal_r1_r1_top_top__t1
 BV BOUND     X_o1_goal_r1_r2_top_side__t1
 BV BOUND     X_o1_goal_r2_r2_side_side__t1
 BV BOUND     X_o2_start_r1_r1_top_top__t1
 BV BOUND     X_o3_start_r2_r2_side_side__t1
ENDATA
