mod solid;
