* mrgc: the model's names of the columns and rows the file names otherwise
*   col X_o1_goal_r1_r1_top_top__t1 = X(o1,goal,r1,r1,top,top)@1
*   col X_o1_goal_r1_r2_top_side__t1 = X(o1,goal,r1,r2,top,side)@1
*   col X_o1_goal_r2_r2_side_side__t1 = X(o1,goal,r2,r2,side,side)@1
*   col X_o2_start_r1_r1_top_top__t1 = X(o2,start,r1,r1,top,top)@1
*   col X_o3_start_r2_r2_side_side__t1 = X(o3,start,r2,r2,side,side)@1
*   row c3_o2_3_1__0 = c3[o2,3,1] (row 0)
*   row c3_o3_4_1__1 = c3[o3,4,1] (row 1)
*   row c4_r1__2 = c4[r1] (row 2)
*   row c4_r2__3 = c4[r2] (row 3)
*   row c5_4 = c5 (row 4)
*   row c8_o1__5 = c8[o1] (row 5)
*   row c9_0_o2__6 = c9[0,o2] (row 6)
*   row c9_0_o3__7 = c9[0,o3] (row 7)
*   row c9_1_o2__8 = c9[1,o2] (row 8)
*   row c10_o2__9 = c10[o2] (row 9)
*   row c10_o3__10 = c10[o3] (row 10)
*   row c11_0_o2__11 = c11[0,o2] (row 11)
*   row c12_0_o3__12 = c12[0,o3] (row 12)
*   row c11_1_o2__13 = c11[1,o2] (row 13)
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
